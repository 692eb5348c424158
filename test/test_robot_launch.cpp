// rostest: robot.launch brings up every node of the suite (no simulator), they stay up without input, the
// trackers and planner advertise their outputs, and nothing publishes /clock or ground truth.
#include <gtest/gtest.h>
#include <picker_localisation/TopologicalMap.h>
#include <ros/master.h>
#include <ros/ros.h>

#include <algorithm>
#include <set>

#include "diagnostics_rostest_util.h"

namespace {
std::set<std::string> nodes() {
  std::vector<std::string> v;
  ros::master::getNodes(v);
  return {v.begin(), v.end()};
}
std::set<std::string> topics() {
  ros::master::V_TopicInfo v;
  ros::master::getTopics(v);
  std::set<std::string> out;
  for (const auto& t : v) out.insert(t.name);
  return out;
}
}  // namespace

TEST(RobotLaunch, EveryNodeUpWithoutSimulator) {
  const std::vector<std::string> expected{"/topological_map_server", "/robot_1/robot_state_publisher",
                                          "/gnss_ingest",            "/robot_1/rfid_ranging",
                                          "/robot_1/uwb_ranging",    "/robot_1/leg_detector",
                                          "/robot_1/camera_detector", "/robot_1/nbs_planner",
                                          "/tpf_tracker"};
  std::set<std::string> up;
  for (int i = 0; i < 60 && ros::ok(); ++i) {  // (a slow machine: allow time)
    up = nodes();
    if (std::all_of(expected.begin(), expected.end(), [&](const std::string& n) { return up.count(n); })) break;
    ros::WallDuration(1.0).sleep();
  }
  for (const auto& n : expected) EXPECT_TRUE(up.count(n)) << n << " is not running";
  EXPECT_FALSE(up.count("/farm_sim"));
  // Still up a few seconds later with no sensor input at all.
  ros::WallDuration(3.0).sleep();
  up = nodes();
  for (const auto& n : expected) EXPECT_TRUE(up.count(n)) << n << " died without input";
}

TEST(RobotLaunch, OutputsAdvertisedAndNoSimulation) {
  auto map = ros::topic::waitForMessage<picker_localisation::TopologicalMap>("/picker_localisation/topological_map", ros::Duration(30));
  ASSERT_TRUE(map);
  EXPECT_EQ(map->nodes.size(), 138u);
  std::set<std::string> t;
  for (int i = 0; i < 30 && ros::ok(); ++i) {
    t = topics();
    if (t.count("/pickers/picker_3/belief") && t.count("/robot_1/goal")) break;
    ros::WallDuration(1.0).sleep();
  }
  for (const char* name : {"/pickers/picker_1/belief", "/pickers/picker_1/estimate", "/pickers/picker_1/markers",
                           "/observations", "/robot_1/goal", "/topological_map/markers"})
    EXPECT_TRUE(t.count(name)) << name << " not advertised";
  ros::master::V_TopicInfo infos;
  ros::master::getTopics(infos);
  // getTopics lists published topics only: no clock, no ground truth on a real robot.
  for (const auto& i : infos) {
    EXPECT_NE(i.name, "/clock");
    EXPECT_EQ(i.name.find("ground_truth"), std::string::npos) << i.name;
  }
}

// Every node of the suite reports on /diagnostics (the nodes the master knows, so a node added to robot.launch
// without diagnostics fails here), and the sensor front-ends report the rate of their inputs.
TEST(RobotLaunch, EveryNodePublishesDiagnostics) {
  ros::NodeHandle nh;
  std::set<std::string> nodes;
  for (int i = 0; i < 60 && ros::ok() && nodes.size() < 9; ++i) {  // all nine up (robot_state_publisher too)
    nodes = diagnostics_test::graphNodes({"/rosout"});
    ros::WallDuration(1.0).sleep();
  }
  // Not ours: robot_state_publisher (Debian's) has no diagnostics.
  nodes.erase("/robot_1/robot_state_publisher");
  ASSERT_GE(nodes.size(), 8u);
  const auto seen = diagnostics_test::collect(nh, nodes, 30.0);
  for (const auto& n : nodes) EXPECT_TRUE(seen.count(n)) << n << " publishes nothing on /diagnostics";
  // The inputs status with its rate line, before any input arrived.
  for (const auto& [node, input] : std::vector<std::pair<std::string, std::string>>{
           {"/robot_1/leg_detector", "scans"},
           {"/robot_1/camera_detector", "images"},
           {"/gnss_ingest", "fixes"},
           {"/tpf_tracker", "observations"},
           {"/robot_1/nbs_planner", "beliefs"}}) {
    if (!seen.count(node) || !seen.at(node).count("inputs")) {
      ADD_FAILURE() << node << " has no inputs status";
      continue;
    }
    const auto& st = seen.at(node).at("inputs");
    bool found = false;
    for (const auto& kv : st.values)
      if (kv.key == input + " received / rate [Hz] / newest [s ago]") found = kv.value.rfind("0 / ", 0) == 0;
    EXPECT_TRUE(found) << node << ": no '" << input << "' line with 0 received";
    EXPECT_EQ(st.level, diagnostic_msgs::DiagnosticStatus::OK) << node << ": " << st.message;
  }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_robot_launch");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
