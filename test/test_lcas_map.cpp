// rostest (test/lcas_map.test): the map as an LCAS robot publishes it, a std_msgs/String holding the tmap2 as
// JSON on /topological_map_2, with meta.datum_latitude / datum_longitude and a transformation that rotates
// the node poses by 90 degrees and shifts them by (40, -25) m. gnss_ingest has no datum file, so only the
// map's datum can turn a picker's fix into map coordinates; the tracker must name the node where the fix puts
// the picker on /picker_1/current_node. Before it, a truncated map message: refused with one error and a
// diagnostics ERROR by every node, which stay up and take the valid map that follows.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <picker_localisation/PickerBelief.h>
#include <ros/master.h>
#include <ros/ros.h>
#include <sensor_msgs/NavSatFix.h>
#include <std_msgs/String.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/ros/ranging_nodes.h"
#include "picker_localisation/topology/map_io.h"
#include "tmap_edits.h"
#include "wait_deadline.h"

using namespace picker_localisation;

namespace {

// A YAML document as JSON (as Python's json.dumps of the loaded tmap2 would write it).
void writeJson(const YAML::Node& n, std::ostream& out) {
  if (n.IsMap()) {
    out << '{';
    bool first = true;
    for (const auto& kv : n) {
      out << (first ? "" : ",") << '"' << kv.first.as<std::string>() << "\":";
      writeJson(kv.second, out);
      first = false;
    }
    out << '}';
  } else if (n.IsSequence()) {
    out << '[';
    for (std::size_t i = 0; i < n.size(); ++i) {
      if (i) out << ',';
      writeJson(n[i], out);
    }
    out << ']';
  } else if (n.IsNull()) {
    out << "null";
  } else {
    const std::string s = n.Scalar();
    char* end = nullptr;
    std::strtod(s.c_str(), &end);
    if (!s.empty() && end && *end == '\0') {
      out << s;
    } else {
      out << '"';
      for (char c : s) {
        if (c == '"' || c == '\\') out << '\\';
        out << c;
      }
      out << '"';
    }
  }
}

constexpr double kDatumLatitude = 52.1, kDatumLongitude = 1.2;  // not config/datum.yaml's

std_msgs::String asJson(const YAML::Node& doc) {
  std::ostringstream json;
  writeJson(doc, json);
  std_msgs::String text;
  text.data = json.str();
  return text;
}

}  // namespace

TEST(LcasMap, CurrentNodeOnAJsonMapWithDatumAndTransformation) {
  ros::NodeHandle nh, pnh("~");
  std::string map_file;
  ASSERT_TRUE(pnh.getParam("map_file", map_file));
  YAML::Node doc = YAML::LoadFile(map_file);
  doc["meta"]["datum_latitude"] = kDatumLatitude;
  doc["meta"]["datum_longitude"] = kDatumLongitude;
  doc["transformation"]["rotation"]["w"] = std::sqrt(0.5);
  doc["transformation"]["rotation"]["x"] = 0.0;
  doc["transformation"]["rotation"]["y"] = 0.0;
  doc["transformation"]["rotation"]["z"] = std::sqrt(0.5);
  doc["transformation"]["translation"]["x"] = 40.0;
  doc["transformation"]["translation"]["y"] = -25.0;
  std::ostringstream json;
  writeJson(doc, json);
  std_msgs::String text;
  text.data = json.str();
  ASSERT_EQ(text.data.front(), '{');

  // Where the nodes are in the map frame: rotated and shifted, as the nodes must read them.
  const topology::TopologicalMap file_map = topology::loadMap(map_file);
  const topology::TopologicalMap lcas_map = topology::parseMap(text.data, "/topological_map_2");
  ASSERT_EQ(lcas_map.numNodes(), file_map.numNodes());
  ASSERT_TRUE(lcas_map.datum().has_value());
  const topology::NodeIndex target = lcas_map.laneNodes(3)[lcas_map.laneNodes(3).size() / 2];
  const Eigen::Vector2d p_file = file_map.position2d(target), p_map = lcas_map.position2d(target);
  EXPECT_NEAR(p_map.x(), 40.0 - p_file.y(), 1e-6);
  EXPECT_NEAR(p_map.y(), -25.0 + p_file.x(), 1e-6);
  EXPECT_GT((p_map - p_file).norm(), 20.0);  // the test cannot pass with the transformation ignored

  // First a truncated map message (a map manager cut off mid-send): every node reading the topic refuses it
  // with one ERROR and a diagnostics ERROR, stays up and waits; the valid map that follows is taken.
  std::mutex diag_mutex;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> map_errors;  // by node
  ros::Subscriber diag_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
        std::lock_guard<std::mutex> lock(diag_mutex);
        for (const auto& st : a->status)
          if (st.level == diagnostic_msgs::DiagnosticStatus::ERROR &&
              st.name.find(": map") != std::string::npos)
            map_errors[st.name.substr(0, st.name.find(": map"))] = st;
      });
  ros::Publisher map_pub = nh.advertise<std_msgs::String>("/topological_map_2", 1, /*latch=*/true);
  std_msgs::String truncated;
  truncated.data = text.data.substr(0, text.data.size() / 3);
  // True once both nodes reported a map ERROR (or at the deadline, false).
  auto bothRefused = [&] {
    const ros::WallTime by = ros::WallTime::now() + ros::WallDuration(test_wait::kDeadline);
    while (ros::ok() && ros::WallTime::now() < by) {
      {
        std::lock_guard<std::mutex> lock(diag_mutex);
        if (map_errors.count("gnss_ingest") && map_errors.count("tpf_tracker")) return true;
      }
      ros::WallDuration(0.1).sleep();
    }
    return false;
  };
  map_pub.publish(truncated);
  bothRefused();
  {
    std::lock_guard<std::mutex> lock(diag_mutex);
    ASSERT_TRUE(map_errors.count("gnss_ingest") && map_errors.count("tpf_tracker"))
        << "no diagnostics ERROR for the truncated map from gnss_ingest and tpf_tracker";
    for (const auto& kv : map_errors) {
      EXPECT_NE(kv.second.message.find("/topological_map_2"), std::string::npos) << kv.second.message;
      EXPECT_NE(kv.second.message.find("YAML syntax error"), std::string::npos) << kv.second.message;
    }
  }
  std::vector<std::string> nodes;
  ASSERT_TRUE(ros::master::getNodes(nodes));
  for (const char* node : {"/gnss_ingest", "/tpf_tracker"})
    EXPECT_NE(std::find(nodes.begin(), nodes.end(), node), nodes.end()) << node << " died on the bad map";
  map_pub.publish(text);
  std::mutex m;
  std::string current;
  ros::Subscriber sub =
      nh.subscribe<std_msgs::String>("/picker_1/current_node", 5, [&](const std_msgs::String::ConstPtr& s) {
        std::lock_guard<std::mutex> lock(m);
        current = s->data;
      });
  ros::Publisher fix_pub = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_1/fix", 10);

  core::DatumConfig c;
  c.latitude = kDatumLatitude;
  c.longitude = kDatumLongitude;
  const core::GeodeticDatum datum(c);
  const std::string expected = lcas_map.node(target).name;
  // Fixes where the picker stands, every 0.5 s, until current_node names `node` (or the deadline).
  auto fixesUntilCurrentNodeIs = [&](const std::string& node) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(test_wait::kDeadline);
    while (ros::ok() && ros::WallTime::now() < end) {
      fix_pub.publish(ros_adapter::navSatFixAt(datum, p_map, ros::Time::now(), 0.3));
      ros::WallDuration(0.5).sleep();
      std::lock_guard<std::mutex> lock(m);
      if (current == node) return;
    }
  };
  fixesUntilCurrentNodeIs(expected);
  {
    std::lock_guard<std::mutex> lock(m);
    ASSERT_EQ(current, expected) << "the picker stands at " << expected << " (" << p_map.transpose()
                                 << " in the map frame)";
  }

  // The map manager edits the map while the picker is tracked: the picker's node renamed, two nodes of
  // another lane removed, a third lane's nodes moved 0.4 m. Within seconds current_node names the renamed
  // node (a node of the new map, where the picker stands), the belief keeps its mass there, no node restarts.
  std::mutex belief_mutex;
  picker_localisation::PickerBelief belief;
  ros::Subscriber belief_sub = nh.subscribe<picker_localisation::PickerBelief>(
      "/pickers/picker_1/belief", 5, [&](const picker_localisation::PickerBelief::ConstPtr& b) {
        std::lock_guard<std::mutex> lock(belief_mutex);
        belief = *b;
      });
  YAML::Node edited = YAML::Clone(doc);
  const std::string renamed = expected + "_renamed";
  tmap_edits::renameNode(edited, expected, renamed);
  const auto& far_lane = lcas_map.laneNodes(0);
  for (std::size_t k = 0; k < 2; ++k) tmap_edits::removeNode(edited, lcas_map.node(far_lane[k]).name);
  const auto& moved_lane = lcas_map.laneNodes(1);
  for (YAML::Node n : edited["nodes"])
    for (topology::NodeIndex i : moved_lane)
      if (n["node"]["name"].as<std::string>() == lcas_map.node(i).name)
        n["node"]["pose"]["position"]["x"] = n["node"]["pose"]["position"]["x"].as<double>() + 0.4;
  const std_msgs::String edited_text = asJson(edited);
  const topology::TopologicalMap edited_map = topology::parseMap(edited_text.data, "/topological_map_2");
  ASSERT_EQ(edited_map.numNodes(), lcas_map.numNodes() - 2);
  ASSERT_TRUE(edited_map.index(renamed).has_value());
  map_pub.publish(edited_text);
  fixesUntilCurrentNodeIs(renamed);
  {
    std::lock_guard<std::mutex> lock(m);
    EXPECT_EQ(current, renamed) << "current_node still names a node the map no longer has";
  }
  // The belief and current_node come on separate connections: wait for a belief on the new map's nodes.
  const ros::WallTime belief_by = ros::WallTime::now() + ros::WallDuration(test_wait::kDeadline);
  while (ros::ok() && ros::WallTime::now() < belief_by) {
    {
      std::lock_guard<std::mutex> lock(belief_mutex);
      if (!belief.nodes.empty() && std::all_of(belief.nodes.begin(), belief.nodes.end(), [&](const std::string& n) {
            return edited_map.index(n).has_value();
          }))
        break;
    }
    fix_pub.publish(ros_adapter::navSatFixAt(datum, p_map, ros::Time::now(), 0.3));
    ros::WallDuration(0.5).sleep();
  }
  {
    std::lock_guard<std::mutex> lock(belief_mutex);
    double near = 0.0;  // mass within 3 m of the picker, on nodes of the new map
    for (std::size_t k = 0; k < belief.nodes.size() && k < belief.masses.size(); ++k) {
      const auto n = edited_map.index(belief.nodes[k]);
      ASSERT_TRUE(n.has_value()) << belief.nodes[k] << " is not a node of the edited map";
      if ((edited_map.position2d(*n) - p_map).norm() < 3.0) near += belief.masses[k];
    }
    EXPECT_GT(near, 0.5) << "the belief lost the picker with the map edit";
  }

  // A map with a non-numeric coordinate, then one with an edge to a missing node: each refused with a
  // diagnostics ERROR by both nodes, the edited map kept.
  for (const char* broken : {"coordinate", "edge"}) {
    YAML::Node bad = YAML::Clone(edited);
    if (std::string(broken) == "coordinate")
      bad["nodes"][5]["node"]["pose"]["position"]["x"] = "twelve";
    else
      bad["nodes"][5]["node"]["edges"][0]["node"] = "NoSuchWayPoint";
    {
      std::lock_guard<std::mutex> lock(diag_mutex);
      map_errors.clear();
    }
    map_pub.publish(asJson(bad));
    EXPECT_TRUE(bothRefused()) << "a map with a bad " << broken << " was not refused by both nodes";
  }
  ros::WallDuration(1.0).sleep();
  ASSERT_TRUE(ros::master::getNodes(nodes));
  for (const char* node : {"/gnss_ingest", "/tpf_tracker"})
    EXPECT_NE(std::find(nodes.begin(), nodes.end(), node), nodes.end()) << node << " died on a map edit";
  std::lock_guard<std::mutex> lock(m);
  EXPECT_EQ(current, renamed) << "a refused map moved the picker";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_lcas_map");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const int rc = RUN_ALL_TESTS();
  spinner.stop();
  return rc;
}
