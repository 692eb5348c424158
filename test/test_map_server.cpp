// rostest: topological_map_server publishes the Riseholme map and its markers latched, and serves the map.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <picker_localisation/GetTopologicalMap.h>
#include <picker_localisation/TopologicalMap.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>
#include <yaml-cpp/yaml.h>

#include <fstream>

#include "tmap_edits.h"

namespace {
template <class M>
boost::shared_ptr<const M> waitLatched(const std::string& topic) {
  // A subscriber that connects after the publish only sees the message because it is latched.
  return ros::topic::waitForMessage<M>(topic, ros::Duration(30.0));
}
}  // namespace

TEST(MapServer, LatchedMap) {
  ros::Duration(0.5).sleep();  // connect after the server published
  auto map = waitLatched<picker_localisation::TopologicalMap>("/picker_localisation/topological_map");
  ASSERT_TRUE(map);
  EXPECT_EQ(map->nodes.size(), 138u);
  EXPECT_EQ(map->edges.size(), 308u);
  EXPECT_EQ(map->lanes.size(), 12u);
  EXPECT_EQ(map->header.frame_id, "map");
  EXPECT_EQ(map->name, "riseholme_rtk");
  for (const auto& e : map->edges) {
    ASSERT_LT(e.source, map->nodes.size());
    ASSERT_LT(e.target, map->nodes.size());
    EXPECT_GT(e.length, 0.0);
  }
}

TEST(MapServer, LatchedMarkers) {
  auto markers = waitLatched<visualization_msgs::MarkerArray>("/topological_map/markers");
  ASSERT_TRUE(markers);
  ASSERT_GE(markers->markers.size(), 2u);
  EXPECT_EQ(markers->markers[0].ns, "nodes");
  EXPECT_EQ(markers->markers[0].points.size(), 138u);
  EXPECT_EQ(markers->markers[1].ns, "edges");
  EXPECT_EQ(markers->markers[1].points.size(), 308u);  // 154 undirected edges, 2 points each
}

TEST(MapServer, Service) {
  ASSERT_TRUE(ros::service::waitForService("/get_topological_map", ros::Duration(30.0)));
  picker_localisation::GetTopologicalMap srv;
  ASSERT_TRUE(ros::service::call("/get_topological_map", srv));
  EXPECT_EQ(srv.response.map.nodes.size(), 138u);
}

TEST(MapServer, Diagnostics) {
  bool found = false;
  for (int i = 0; i < 10 && !found; ++i) {
    auto d =
        ros::topic::waitForMessage<diagnostic_msgs::DiagnosticArray>("/diagnostics", ros::Duration(60.0));
    ASSERT_TRUE(d);
    for (const auto& s : d->status)
      if (s.name.find("topological map") != std::string::npos) {
        found = true;
        EXPECT_EQ(s.level, diagnostic_msgs::DiagnosticStatus::OK);
        bool nodes = false;
        for (const auto& kv : s.values) nodes |= (kv.key == "nodes" && kv.value == "138");
        EXPECT_TRUE(nodes);
      }
  }
  EXPECT_TRUE(found);
}

// A map manager edited the file: ~reload publishes the new map (one node fewer) with what changed; a file
// that cannot be read is refused with the reason and the current map stays on the topic.
TEST(MapServer, ReloadPublishesTheEditedFileAndRefusesABrokenOne) {
  ros::NodeHandle nh;
  std::string original;
  ASSERT_TRUE(nh.getParam("/topological_map_server/map_file", original));
  YAML::Node doc = YAML::LoadFile(original);
  tmap_edits::removeNode(doc, doc["nodes"][doc["nodes"].size() - 1]["node"]["name"].as<std::string>());
  const std::string edited = testing::TempDir() + "/map_server_edited.tmap2";
  {
    std::ofstream out(edited);
    out << doc;
  }
  std::size_t latest_nodes = 0;
  ros::Subscriber sub = nh.subscribe<picker_localisation::TopologicalMap>(
      "/picker_localisation/topological_map", 2,
      [&](const picker_localisation::TopologicalMap::ConstPtr& m) { latest_nodes = m->nodes.size(); });
  ASSERT_TRUE(ros::service::waitForService("/topological_map_server/reload", ros::Duration(30.0)));
  nh.setParam("/topological_map_server/map_file", edited);
  std_srvs::Trigger reload;
  ASSERT_TRUE(ros::service::call("/topological_map_server/reload", reload));
  EXPECT_TRUE(reload.response.success) << reload.response.message;
  EXPECT_NE(reload.response.message.find("+0 -1 nodes"), std::string::npos) << reload.response.message;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(30.0);
  while (latest_nodes != 137u && ros::WallTime::now() < end) {
    ros::spinOnce();
    ros::WallDuration(0.05).sleep();
  }
  EXPECT_EQ(latest_nodes, 137u);
  nh.setParam("/topological_map_server/map_file", edited + ".missing");
  std_srvs::Trigger broken;
  ASSERT_TRUE(ros::service::call("/topological_map_server/reload", broken));
  EXPECT_FALSE(broken.response.success);
  EXPECT_NE(broken.response.message.find("current map stays"), std::string::npos) << broken.response.message;
  auto still = waitLatched<picker_localisation::TopologicalMap>("/picker_localisation/topological_map");
  ASSERT_TRUE(still);
  EXPECT_EQ(still->nodes.size(), 137u);
  nh.setParam("/topological_map_server/map_file", original);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_map_server");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
