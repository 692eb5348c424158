// dispatch::CallDispatcher on the synthetic polytunnel (12 lanes 1.5 m apart, nodes r<k>_<i> 3 m apart,
// headland H<k> / T<k>): assignment by expected travel time over the belief, the 1-median target (one lane:
// in it; two lanes: their shared lane end), arrival only from the serving robot's sighting within
// arrival_distance, loading, storage, cancel, refused calls and options.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include "picker_localisation/dispatch/call_dispatcher.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;
using dispatch::CallDispatcher;
using dispatch::CallState;
using dispatch::DispatcherOptions;
using topology::NodeIndex;

namespace {

std::shared_ptr<const topology::TopologicalMap> polytunnel() {
  return std::make_shared<const topology::TopologicalMap>(
      topology::makePolytunnelMap(topology::PolytunnelSpec()));
}

NodeIndex node(const topology::TopologicalMap& map, const std::string& name) {
  return *map.index(name);
}

DispatcherOptions options() {
  DispatcherOptions o;
  o.load_time = 30.0;
  o.storage_node = "H0";
  return o;
}

}  // namespace

TEST(CallDispatcher, TheRobotWithTheLeastExpectedTravelIsSentIntoTheBeliefsLane) {
  auto map = polytunnel();
  CallDispatcher d(map, options(), {"robot_1", "robot_2"});
  // robot_1 at lane 0's entry, robot_2 at lane 10's; the picker is believed in lane 8 (nodes 3-5).
  d.setRobotNode("robot_1", node(*map, "H0"));
  d.setRobotNode("robot_2", node(*map, "H10"));
  ASSERT_TRUE(
      d.setBelief("picker_1", {node(*map, "r8_3"), node(*map, "r8_4"), node(*map, "r8_5")}, {1, 2, 1}));
  const auto id = d.call("picker_1", 100.0);
  ASSERT_TRUE(id);
  EXPECT_EQ(d.find(*id)->state, CallState::kQueued);
  auto goals = d.update(100.5);
  ASSERT_EQ(goals.size(), 1u);
  EXPECT_EQ(goals[0].robot_id, "robot_2");
  EXPECT_EQ(goals[0].node, node(*map, "r8_4"));  // the belief's 1-median: its mass centre in the lane
  EXPECT_EQ(d.find(*id)->state, CallState::kAssigned);
  EXPECT_EQ(d.servedBy("robot_2")->id, *id);
  EXPECT_EQ(d.servedBy("robot_1"), nullptr);
  EXPECT_TRUE(d.update(101.0).empty());  // nothing changed: no new goal
  EXPECT_EQ(d.find(*id)->state, CallState::kOnTheWay);
  // Expected distance by hand: from H10 to lane 8 node i = 2 lanes of headland (3 m) + 3 + 3 i.
  const double h = 2 * 1.5, e = 0.25 * (h + 3 + 9) + 0.5 * (h + 3 + 12) + 0.25 * (h + 3 + 15);
  EXPECT_NEAR(d.expectedDistance(node(*map, "H10"), "picker_1"), e, 1e-9);
}

TEST(CallDispatcher, TheTargetFollowsTheBeliefIntoTheLaneItSettlesIn) {
  auto map = polytunnel();
  CallDispatcher d(map, options(), {"robot_1"});
  d.setRobotNode("robot_1", node(*map, "H0"));
  // Half in lane 4, half in lane 5 near the entry: either lane end is a 1-median (the same expected path);
  // once the belief settles in lane 5 the target is its mass centre there.
  d.setBelief("picker_1", {node(*map, "r4_1"), node(*map, "r5_1")}, {1, 1});
  d.call("picker_1", 0.0);
  auto goals = d.update(0.0);
  ASSERT_EQ(goals.size(), 1u);
  const NodeIndex split_target = goals[0].node;
  EXPECT_TRUE(split_target == node(*map, "r4_1") || split_target == node(*map, "r5_1"));
  d.setBelief("picker_1", {node(*map, "r5_1"), node(*map, "r5_2")}, {3, 1});
  goals = d.update(5.0);
  ASSERT_EQ(goals.size(), 1u);
  EXPECT_EQ(goals[0].node, node(*map, "r5_1"));
}

TEST(CallDispatcher, ArrivalOnlyFromTheServingRobotsOwnSightingThenLoadingStorageDone) {
  auto map = polytunnel();
  CallDispatcher d(map, options(), {"robot_1", "robot_2"});
  d.setRobotNode("robot_1", node(*map, "H3"));
  d.setRobotNode("robot_2", node(*map, "T11"));
  d.setBelief("picker_1", {node(*map, "r3_2")}, {1});
  const auto id = *d.call("picker_1", 10.0);
  d.update(10.0);
  ASSERT_EQ(d.find(id)->robot_id, "robot_1");
  d.setRobotNode("robot_1", node(*map, "r3_2"));  // at the target: not arrival
  d.update(20.0);
  EXPECT_EQ(d.find(id)->state, CallState::kOnTheWay);
  EXPECT_FALSE(d.sighting("robot_2", "picker_1", 21.0, 0.5));  // another robot's sighting
  EXPECT_FALSE(d.sighting("robot_1", "picker_1", 21.0, 2.5));  // too far (arrival_distance 1.5 m here)
  EXPECT_FALSE(d.sighting("robot_1", "picker_2", 21.0, 0.5));  // another picker
  EXPECT_TRUE(d.sighting("robot_1", "picker_1", 22.0, 1.4));
  EXPECT_EQ(d.find(id)->state, CallState::kArrived);
  EXPECT_DOUBLE_EQ(d.find(id)->arrived_at, 22.0);
  EXPECT_TRUE(d.update(51.9).empty());  // loading: 30 s
  auto goals = d.update(52.0);
  ASSERT_EQ(goals.size(), 1u);
  EXPECT_EQ(goals[0].node, node(*map, "H0"));
  EXPECT_EQ(goals[0].state, CallState::kToStorage);
  EXPECT_EQ(d.servedBy("robot_1")->id, id);  // busy until the trays are delivered
  d.setRobotNode("robot_1", node(*map, "H0"));
  d.update(60.0);
  EXPECT_EQ(d.find(id)->state, CallState::kDone);
  EXPECT_DOUBLE_EQ(d.find(id)->done_at, 60.0);
  EXPECT_EQ(d.servedBy("robot_1"), nullptr);
}

TEST(CallDispatcher, QueuedWithoutBeliefOrFreeRobotOneRobotPerCallCancelAndRefusals) {
  auto map = polytunnel();
  CallDispatcher d(map, options(), {"robot_1"});
  d.setRobotNode("robot_1", node(*map, "H0"));
  std::string error;
  EXPECT_FALSE(d.call("", 1.0, &error));
  const auto a = *d.call("picker_1", 1.0);
  EXPECT_FALSE(d.call("picker_1", 2.0, &error));  // its call is open
  EXPECT_NE(error.find("open call"), std::string::npos);
  EXPECT_TRUE(d.update(2.0).empty());  // no belief of picker_1 yet: queued
  EXPECT_EQ(d.find(a)->state, CallState::kQueued);
  d.setBelief("picker_1", {node(*map, "r2_2")}, {1});
  d.setBelief("picker_2", {node(*map, "r6_2")}, {1});
  const auto b = *d.call("picker_2", 3.0);
  auto goals = d.update(4.0);
  ASSERT_EQ(goals.size(), 1u);  // one robot: the first call gets it, the second waits
  EXPECT_EQ(goals[0].call_id, a);
  EXPECT_EQ(d.find(b)->state, CallState::kQueued);
  EXPECT_TRUE(d.cancel(a, 5.0));
  EXPECT_FALSE(d.cancel(a, 5.0, &error));
  goals = d.update(6.0);
  ASSERT_EQ(goals.size(), 1u);  // the robot is free again: the second call
  EXPECT_EQ(goals[0].call_id, b);
  EXPECT_TRUE(d.call("picker_1", 7.0).has_value());  // the cancelled call is closed
  // Unusable input changes nothing.
  EXPECT_FALSE(d.setBelief("picker_3", {}, {}));
  EXPECT_FALSE(d.setBelief("picker_3", {node(*map, "r1_1")}, {0.0}));
  EXPECT_FALSE(d.setRobotNode("robot_9", 0));
  EXPECT_FALSE(d.setRobotNode("robot_1", map->numNodes()));
}

TEST(CallDispatcher, OptionsFromYamlAndValidation) {
  std::vector<std::string> unknown;
  const DispatcherOptions o = DispatcherOptions::fromYaml(
      YAML::Load("{load_time: 90, storage_node: H0, arival_distance: 3}"), &unknown);
  EXPECT_DOUBLE_EQ(o.load_time, 90.0);
  EXPECT_EQ(o.storage_node, "H0");
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_NE(unknown[0].find("arrival_distance"), std::string::npos);
  EXPECT_THROW(DispatcherOptions::fromYaml(YAML::Load("{robot_speed: 0}")), std::runtime_error);
  auto map = polytunnel();
  DispatcherOptions bad_storage;
  bad_storage.storage_node = "nowhere";
  EXPECT_THROW(CallDispatcher(map, bad_storage, {"robot_1"}), std::invalid_argument);
  EXPECT_THROW(CallDispatcher(map, DispatcherOptions(), {}), std::invalid_argument);
}

TEST(CallDispatcher, AnRfidReadIsArrivalOnlyWhenStrong) {
  auto map = polytunnel();
  DispatcherOptions o = options();  // arrival_min_rssi -48 dBm
  o.arrival_by_lidar = false;
  CallDispatcher d(map, o, {"robot_1"});
  d.setRobotNode("robot_1", node(*map, "H2"));
  d.setBelief("picker_1", {node(*map, "r2_4")}, {1});
  const auto id = *d.call("picker_1", 0.0);
  d.update(0.0);
  EXPECT_FALSE(d.rfidRead("robot_1", "picker_1", 5.0, -58.0));  // read at ~4 m: not there yet
  EXPECT_FALSE(d.lidarPerson("robot_1", "picker_1", 6.0, 1.0));  // LiDAR identity switched off
  EXPECT_EQ(d.find(id)->state, CallState::kAssigned);
  EXPECT_FALSE(d.rfidRead("robot_1", "picker_1", 8.0, -49.0));
  EXPECT_TRUE(d.rfidRead("robot_1", "picker_1", 9.0, -47.5));
  EXPECT_EQ(d.find(id)->state, CallState::kArrived);
}

TEST(CallDispatcher, WithACommitShareTheRobotWaitsAtTheLaneEndUntilTheBeliefCommits) {
  auto map = polytunnel();
  DispatcherOptions o = options();
  o.commit_share = 0.8;
  o.commit_wait = 30.0;
  CallDispatcher d(map, o, {"robot_1"});
  d.setRobotNode("robot_1", node(*map, "H0"));
  // 60/40 between lanes 4 and 5, deep in the lanes: neither is committed to.
  d.setBelief("picker_1", {node(*map, "r4_6"), node(*map, "r5_6")}, {0.6, 0.4});
  const auto id = *d.call("picker_1", 0.0);
  auto goals = d.update(0.0);
  ASSERT_EQ(goals.size(), 1u);
  // The lane end with the least expected path to the picker: lane 4's far end (the mass is nearer that end).
  EXPECT_EQ(goals[0].node, node(*map, "r4_9"));
  d.setRobotNode("robot_1", node(*map, "r4_9"));
  EXPECT_TRUE(d.update(10.0).empty());  // waits there (since 10 s)
  // The belief commits to lane 5: the robot goes in.
  d.setBelief("picker_1", {node(*map, "r4_6"), node(*map, "r5_6")}, {0.1, 0.9});
  goals = d.update(20.0);
  ASSERT_EQ(goals.size(), 1u);
  EXPECT_EQ(goals[0].node, node(*map, "r5_6"));
  // Uncommitted again, but the robot waited commit_wait at the lane end: it enters the likelier lane.
  d.setBelief("picker_1", {node(*map, "r4_6"), node(*map, "r5_6")}, {0.6, 0.4});
  goals = d.update(25.0);
  EXPECT_TRUE(goals.empty() || goals[0].node == node(*map, "r4_9"));
  goals = d.update(41.0);
  ASSERT_FALSE(goals.empty());
  EXPECT_EQ(goals.back().node, node(*map, "r4_6"));
  EXPECT_EQ(d.find(id)->robot_id, "robot_1");
}

TEST(CallDispatcher, AnIdentifiedLidarPersonNearTheRobotIsArrival) {
  auto map = polytunnel();
  CallDispatcher d(map, options(), {"robot_1"});
  d.setRobotNode("robot_1", node(*map, "H2"));
  d.setBelief("picker_1", {node(*map, "r2_4")}, {1});
  const auto id = *d.call("picker_1", 0.0);
  d.update(0.0);
  EXPECT_FALSE(d.lidarPerson("robot_1", "picker_1", 6.0, 1.6));  // beyond arrival_distance (1.5 m)
  EXPECT_TRUE(d.lidarPerson("robot_1", "picker_1", 7.0, 1.4));
  EXPECT_EQ(d.find(id)->state, CallState::kArrived);
}
