// dispatch::CallDispatcher on the synthetic polytunnel (12 lanes 1.5 m apart, nodes r<k>_<i> 3 m apart,
// headland H<k> / T<k>): assignment by expected travel time over the belief, the 1-median target (one lane:
// in it; two lanes: their shared lane end), arrival only from the serving robot's sighting within
// arrival_distance, loading, storage, cancel, refused calls and options.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <limits>

#include "picker_localisation/dispatch/call_dispatcher.h"
#include "picker_localisation/dispatch/call_input.h"
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
  o.commit_share = 0.0;  // the 1-median alone; committing to a lane has its own test
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
  // The farm's call log line: every time the call passed, the wait from call to arrival, the last target.
  EXPECT_EQ(
      dispatch::callLogHeader(),
      "call_id,picker_id,robot_id,state,called,assigned,arrived,loaded,done,call_to_arrival_s,target_node");
  EXPECT_EQ(dispatch::callLogLine(*d.find(id), *map),
            std::to_string(id) + ",picker_1,robot_1,done,10,10,22,52,60,12,H0");
  // A sighting stamped before the call (the robot stood by the picker when it called) is arrival at the call.
  d.setRobotNode("robot_1", node(*map, "r3_2"));
  const auto early = *d.call("picker_1", 65.0);
  d.update(65.0);
  ASSERT_EQ(d.find(early)->robot_id, "robot_1");
  EXPECT_TRUE(d.sighting("robot_1", "picker_1", 64.8, 0.5));
  EXPECT_DOUBLE_EQ(d.find(early)->arrived_at, 65.0);
  const auto open = *d.call("picker_2", 70.0);
  EXPECT_EQ(dispatch::callLogLine(*d.find(open), *map), std::to_string(open) + ",picker_2,,queued,70,,,,,,");
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
  EXPECT_DOUBLE_EQ(d.find(id)->holding_since, 10.0);  // the robot held at the lane end from 10 s to 20 s
  EXPECT_DOUBLE_EQ(d.find(id)->hold_ended, 20.0);
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
  // Near, but named less surely than arrival_min_probability: not arrival.
  EXPECT_FALSE(d.lidarPerson("robot_1", "picker_1", 6.5, 1.0, options().arrival_min_probability - 0.01));
  EXPECT_NE(d.find(id)->state, CallState::kArrived);
  EXPECT_TRUE(d.lidarPerson("robot_1", "picker_1", 7.0, 1.4));
  EXPECT_EQ(d.find(id)->state, CallState::kArrived);
}

TEST(CallInput, TheCarAppsJsonIsReadOrRefusedWithTheReason) {
  std::string error;
  auto c = dispatch::parseCarMessage(
      R"({"user": "picker_7", "lat": 53.268, "long": -0.524, "row": 3, "state": "CALLED", "accu": 4.5})",
      &error);
  ASSERT_TRUE(c) << error;
  EXPECT_EQ(c->picker_id, "picker_7");
  EXPECT_TRUE(c->has_fix);
  EXPECT_DOUBLE_EQ(c->latitude, 53.268);
  EXPECT_DOUBLE_EQ(c->longitude, -0.524);
  EXPECT_EQ(c->row, "3");
  EXPECT_FALSE(c->cancel);
  c = dispatch::parseCarMessage(R"({"user": "picker_7", "state": "cancel"})");
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->cancel);
  EXPECT_FALSE(c->has_fix);
  for (const char* bad : {R"({"user": "picker_7", "lat": )", "[1, 2]", R"({"lat": 53.2, "long": -0.5})",
                          R"({"user": "", "lat": 53.2, "long": -0.5})", R"({"user": "p", "lat": 53.2})",
                          R"({"user": "p", "lat": "north", "long": -0.5})", "", "null"}) {
    error.clear();
    EXPECT_FALSE(dispatch::parseCarMessage(bad, &error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
}

TEST(CallInput, AFixOrRowTheMapCannotUseIsLeftOutWithANote) {
  auto map = polytunnel();
  core::DatumConfig dc;
  dc.latitude = 53.268;
  dc.longitude = -0.524;
  const core::GeodeticDatum datum(dc);
  dispatch::CallInput in;
  in.picker_id = "picker_1";
  in.has_fix = true;
  const Eigen::Vector2d on_map = map->position2d(node(*map, "r4_2"));
  const Eigen::Vector2d ll = datum.toLatLon(on_map);
  in.latitude = ll.x();
  in.longitude = ll.y();
  in.row = "4";
  auto checked = dispatch::checkCall(in, *map, &datum, 30.0);
  EXPECT_TRUE(checked.note.empty()) << checked.note;
  ASSERT_TRUE(checked.fix);
  EXPECT_LT((*checked.fix - on_map).norm(), 0.01);
  EXPECT_EQ(checked.row_lane, map->lane(node(*map, "r4_2")));  // "4" names row_4
  in.row = "row_4";
  EXPECT_EQ(dispatch::checkCall(in, *map, &datum, 30.0).row_lane, map->lane(node(*map, "r4_2")));
  // Off the map, NaN, no datum, an unknown row: left out, each with its reason.
  in.latitude += 0.01;  // about 1.1 km north
  in.row = "row_99";
  checked = dispatch::checkCall(in, *map, &datum, 30.0);
  EXPECT_FALSE(checked.fix);
  EXPECT_EQ(checked.row_lane, topology::kNoLane);
  EXPECT_NE(checked.note.find("off the map"), std::string::npos) << checked.note;
  EXPECT_NE(checked.note.find("row 'row_99' is not a lane"), std::string::npos) << checked.note;
  in.latitude = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(dispatch::checkCall(in, *map, &datum, 30.0).note.find("not a WGS84 position"), std::string::npos);
  in.latitude = ll.x();
  EXPECT_NE(dispatch::checkCall(in, *map, nullptr, 30.0).note.find("no datum"), std::string::npos);
}

TEST(CallInput, TheReportedRowIsEvidenceNotARestriction) {
  auto map = polytunnel();
  const topology::LaneIndex lane = map->lane(node(*map, "r4_2"));
  const core::Observation obs = dispatch::reportedRowObservation(*map, lane, "picker_1", 12.0, 0.2);
  EXPECT_TRUE(obs.identifying);
  EXPECT_EQ(obs.picker_id, "picker_1");
  EXPECT_EQ(obs.sensor, "reported_row");
  EXPECT_DOUBLE_EQ(obs.stamp, 12.0);
  ASSERT_EQ(obs.nodes.size(), map->numNodes());
  for (std::size_t k = 0; k < obs.nodes.size(); ++k)
    EXPECT_DOUBLE_EQ(obs.likelihood[k], map->lane(obs.nodes[k]) == lane ? 1.0 : 0.2);
  EXPECT_TRUE(dispatch::reportedRowObservation(*map, topology::kNoLane, "picker_1", 12.0, 0.2).empty());
}

TEST(CallDispatcher, AnEditedMapKeepsCallsRobotsAndBeliefsByNodeName) {
  auto map = polytunnel();
  CallDispatcher d(map, options(), {"robot_1"});
  d.setRobotNode("robot_1", node(*map, "H0"));
  ASSERT_TRUE(d.setBelief("picker_1", {node(*map, "r8_4")}, {1.0}));
  const auto id = d.call("picker_1", 10.0);
  ASSERT_EQ(d.update(10.0).size(), 1u);
  // The same farm shifted by one lane's worth of nodes in the index order: names stay, indices change.
  topology::PolytunnelSpec spec;
  spec.lanes = 13;  // one more lane: node indices after lane 0 move
  auto edited = std::make_shared<const topology::TopologicalMap>(topology::makePolytunnelMap(spec));
  const topology::MapChange change = topology::compareMaps(*map, *edited);
  d.adoptMap(edited, change);
  EXPECT_EQ(d.find(*id)->target, node(*edited, "r8_4"));
  EXPECT_EQ(d.target("picker_1"), node(*edited, "r8_4"));
  EXPECT_TRUE(d.update(11.0).empty()) << "the target did not move on the farm: no new goal";
  // A change that does not fit the current map, or a map without the storage node, changes nothing.
  EXPECT_THROW(d.adoptMap(map, change), std::invalid_argument);
  DispatcherOptions o = options();
  o.storage_node = "H12";
  CallDispatcher d2(edited, o, {"robot_1"});
  EXPECT_THROW(d2.adoptMap(map, topology::compareMaps(*edited, *map)), std::invalid_argument);
}
