// Map <-> message round trip and the map's markers (no roscore needed).
#include <gtest/gtest.h>

#include <cmath>

#include "picker_localisation/ros/map_conversions.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/topology/map_io.h"

using namespace picker_localisation;

TEST(MapConversions, RoundTripKeepsNodesEdgesAndLanes) {
  topology::TopologicalMap map = topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
  picker_localisation::TopologicalMap msg = ros_adapter::toMsg(map, "map");
  EXPECT_EQ(msg.header.frame_id, "map");
  ASSERT_EQ(msg.nodes.size(), 138u);
  ASSERT_EQ(msg.edges.size(), 308u);
  EXPECT_EQ(msg.lanes.size(), 12u);
  topology::TopologicalMap back = ros_adapter::fromMsg(msg);
  EXPECT_EQ(back.numNodes(), map.numNodes());
  EXPECT_EQ(back.numDirectedEdges(), map.numDirectedEdges());
  EXPECT_EQ(back.numLanes(), map.numLanes());
  for (topology::NodeIndex i = 0; i < map.numNodes(); ++i) {
    EXPECT_EQ(back.node(i).name, map.node(i).name);
    EXPECT_EQ(back.laneNameOf(i), map.laneNameOf(i));
    EXPECT_DOUBLE_EQ(back.node(i).position.x(), map.node(i).position.x());
  }
}

TEST(MapConversions, DatumTravelsWithTheMap) {
  topology::TopologicalMap map = topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
  EXPECT_FALSE(ros_adapter::toMsg(map, "map").has_datum);
  map.setDatum(topology::MapDatum{53.268, -0.524, 7.0});
  picker_localisation::TopologicalMap msg = ros_adapter::toMsg(map, "map");
  EXPECT_TRUE(msg.has_datum);
  const topology::TopologicalMap back = ros_adapter::fromMsg(msg);
  ASSERT_TRUE(back.datum().has_value());
  EXPECT_DOUBLE_EQ(back.datum()->latitude, 53.268);
  EXPECT_DOUBLE_EQ(back.datum()->longitude, -0.524);
  EXPECT_DOUBLE_EQ(back.datum()->altitude, 7.0);
  msg.datum_latitude = std::nan("");
  EXPECT_THROW(ros_adapter::fromMsg(msg), topology::MapError);
}

TEST(MapConversions, BadEdgeIndexIsAnError) {
  picker_localisation::TopologicalMap msg;
  msg.nodes.resize(1);
  msg.nodes[0].name = "a";
  msg.edges.resize(1);
  msg.edges[0].source = 0;
  msg.edges[0].target = 7;
  EXPECT_THROW(ros_adapter::fromMsg(msg), topology::MapError);
}

TEST(MapConversions, MarkersCoverNodesEdgesLabels) {
  topology::TopologicalMap map = topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
  visualization_msgs::MarkerArray m = ros_adapter::mapMarkers(map, "map");
  ASSERT_EQ(m.markers.size(), 2u + 138u);
  EXPECT_EQ(m.markers[0].ns, "nodes");
  EXPECT_EQ(m.markers[0].points.size(), 138u);
  EXPECT_EQ(m.markers[0].colors.size(), 138u);
  EXPECT_EQ(m.markers[1].ns, "edges");
  EXPECT_EQ(m.markers[1].points.size(), 2u * 154u);
  EXPECT_EQ(m.markers[2].ns, "labels");
  EXPECT_EQ(m.markers[2].text, map.node(0).name);
  // Lane colours: two different lanes differ; no-lane is grey.
  auto c0 = ros_adapter::laneColour(0), c1 = ros_adapter::laneColour(1), none = ros_adapter::laneColour(-1);
  EXPECT_TRUE(c0.r != c1.r || c0.g != c1.g || c0.b != c1.b);
  EXPECT_FLOAT_EQ(none.r, none.g);
}

#include "picker_localisation/ros/observation_conversions.h"

TEST(ObservationConversions, RoundTripAndUnknownNodes) {
  topology::TopologicalMap map = topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
  core::Observation obs;
  obs.stamp = 12.5;
  obs.sensor = "gnss";
  obs.picker_id = "picker_1";
  obs.identifying = true;
  obs.nodes = {3, 7};
  obs.likelihood = {0.25, 1.0};
  obs.velocity = Eigen::Vector2d(0.5, -0.1);
  obs.position = Eigen::Vector2d(14.0, -20.0);
  obs.position_covariance << 2.0, 0.1, 0.1, 3.0;
  picker_localisation::Observation msg = ros_adapter::toMsg(obs, map);
  EXPECT_EQ(msg.nodes[0], map.node(3).name);
  EXPECT_DOUBLE_EQ(msg.header.stamp.toSec(), 12.5);
  msg.nodes.push_back("NoSuchNode");
  msg.likelihood.push_back(0.5);
  std::size_t unknown = 0;
  core::Observation back = ros_adapter::fromMsg(msg, map, &unknown);
  EXPECT_EQ(unknown, 1u);
  EXPECT_EQ(back.nodes, obs.nodes);
  EXPECT_EQ(back.likelihood, obs.likelihood);
  EXPECT_EQ(back.sensor, "gnss");
  EXPECT_TRUE(back.identifying);
  ASSERT_TRUE(back.velocity.has_value());
  EXPECT_DOUBLE_EQ(back.velocity->x(), 0.5);
  ASSERT_TRUE(back.position.has_value());
  EXPECT_DOUBLE_EQ(back.position_covariance(1, 1), 3.0);
  EXPECT_DOUBLE_EQ(back.position_covariance(0, 1), 0.1);
  EXPECT_EQ(core::validateObservation(back, map), "");
  // An anonymous person's candidates and their association probabilities come through.
  obs.identifying = false;
  obs.picker_id.clear();
  obs.sensor = "lidar";
  obs.candidate_pickers = {"picker_1", "picker_2"};
  obs.candidate_probabilities = {0.25, 0.5};
  back = ros_adapter::fromMsg(ros_adapter::toMsg(obs, map), map);
  EXPECT_EQ(back.candidate_pickers, obs.candidate_pickers);
  EXPECT_EQ(back.candidate_probabilities, obs.candidate_probabilities);
  EXPECT_EQ(core::validateObservation(back, map), "");
  // Lists of different lengths are caught by validation.
  back.candidate_probabilities.pop_back();
  EXPECT_NE(core::validateObservation(back, map).find("candidate_probabilities"), std::string::npos);
  back.candidate_probabilities = {0.25, 1.5};
  EXPECT_NE(core::validateObservation(back, map), "");
  msg.likelihood.pop_back();
  msg.likelihood.pop_back();
  EXPECT_NE(core::validateObservation(ros_adapter::fromMsg(msg, map), map), "");
}

#include "picker_localisation/ros/detection_markers.h"

TEST(DetectionMarkers, OneBodyAndLabelPerPersonAfterAClear) {
  picker_localisation::PersonDetectionArray people;
  people.header.frame_id = "map";
  people.detections.resize(2);
  people.detections[0].position.x = 3.0;
  people.detections[0].sensor = "lidar";
  people.detections[0].confidence = 0.5;
  people.detections[0].track_id = 7;
  people.detections[1].sensor = "lidar_camera";
  people.detections[1].track_id = -1;
  visualization_msgs::MarkerArray m = ros_adapter::personMarkers(people);
  ASSERT_EQ(m.markers.size(), 5u);
  EXPECT_EQ(m.markers[0].action, visualization_msgs::Marker::DELETEALL);
  EXPECT_DOUBLE_EQ(m.markers[1].pose.position.x, 3.0);
  EXPECT_EQ(m.markers[2].text, "#7 lidar");
  EXPECT_EQ(m.markers[4].text, "lidar_camera");
  EXPECT_GT(m.markers[3].color.g, m.markers[1].color.g);  // camera-confirmed people are green
  EXPECT_EQ(m.markers[1].header.frame_id, "map");
}

TEST(ParamYaml, NestedXmlRpcBecomesYaml) {
  XmlRpc::XmlRpcValue params;
  params["flag"] = true;
  params["count"] = 20;
  params["rate"] = 2.5;
  params["method"] = std::string("tpf");
  params["list"][0] = 1;
  params["list"][1] = std::string("b");
  params["energy"]["capacity"] = 100.0;
  const XmlRpc::XmlRpcValue& in = params;
  YAML::Node y = ros_adapter::toYaml(in);
  ASSERT_TRUE(y.IsMap());
  EXPECT_EQ(y.size(), 6u);
  EXPECT_TRUE(y["flag"].as<bool>());
  EXPECT_EQ(y["count"].as<int>(), 20);
  EXPECT_DOUBLE_EQ(y["count"].as<double>(), 20.0);  // ints read as doubles (e.g. horizon_m: 20)
  EXPECT_DOUBLE_EQ(y["rate"].as<double>(), 2.5);
  EXPECT_EQ(y["method"].as<std::string>(), "tpf");
  ASSERT_TRUE(y["list"].IsSequence());
  ASSERT_EQ(y["list"].size(), 2u);
  EXPECT_EQ(y["list"][0].as<int>(), 1);
  EXPECT_EQ(y["list"][1].as<std::string>(), "b");
  ASSERT_TRUE(y["energy"].IsMap());
  EXPECT_DOUBLE_EQ(y["energy"]["capacity"].as<double>(), 100.0);
  EXPECT_EQ(params.size(), 6);  // the input is left as it was
  EXPECT_TRUE(ros_adapter::toYaml(XmlRpc::XmlRpcValue()).IsNull());  // invalid -> null
}
