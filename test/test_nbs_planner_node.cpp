// rostest of nbs_planner on the Riseholme map (test/nbs_planner.test): beliefs in, goals / candidates /
// markers out, the fleet rule across two robots, the EstimatedNode policy, the what-if service path, and that
// the planner subscribes to no ground-truth topic (asked of the ROS master).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <picker_localisation/CallStatusArray.h>
#include <picker_localisation/GetCandidates.h>
#include <picker_localisation/GoalNode.h>
#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/PickerBeliefArray.h>
#include <picker_localisation/PickerList.h>
#include <picker_localisation/WhatIf.h>
#include <ros/topic.h>
#include <visualization_msgs/MarkerArray.h>

#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <set>

#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/tpf/topological_particle_filter.h"
#include "wait_deadline.h"

using namespace picker_localisation;
using topology::NodeIndex;

namespace {

std::shared_ptr<const topology::TopologicalMap> g_map;
std::unique_ptr<tpf::TopologicalParticleFilter> g_filter;  // picker_2's tracker stand-in
std::atomic<int> g_what_if_calls{0};
std::mutex g_mutex;
std::map<std::string, picker_localisation::GoalNode> g_goals;
bool g_markers = false;
NodeIndex g_robot_node = topology::kInvalidNode;
std::vector<NodeIndex> g_lane_b;  // lane of the uncertain picker_2
NodeIndex g_confident_node = topology::kInvalidNode;

picker_localisation::PickerBelief beliefMsg(const std::string& id, const std::vector<NodeIndex>& nodes,
                                            const std::vector<double>& masses, NodeIndex estimate) {
  picker_localisation::PickerBelief b;
  b.header.stamp = ros::Time::now();
  b.header.frame_id = "map";
  b.picker_id = id;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    b.nodes.push_back(g_map->node(nodes[k]).name);
    b.masses.push_back(masses[k]);
  }
  b.estimated_node = g_map->node(estimate).name;
  b.particle_count = 1000;
  return b;
}

picker_localisation::PickerBelief beliefMsg(const std::string& id, const tpf::Belief& belief) {
  return beliefMsg(id, belief.nodes, belief.masses, belief.map_node);
}

bool whatIf(picker_localisation::WhatIf::Request& req, picker_localisation::WhatIf::Response& res) {
  ++g_what_if_calls;
  std::lock_guard<std::mutex> lock(g_mutex);
  const tpf::Belief b =
      req.with_observation
          ? g_filter->posteriorUnder(ros_adapter::fromMsg(req.observation, *g_map), req.horizon, req.seed)
          : g_filter->predictAhead(req.horizon, req.seed);
  res.success = true;
  res.belief = beliefMsg("picker_2", b);
  return true;
}

void goalCallback(const picker_localisation::GoalNode::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_goals[msg->robot_id] = *msg;
}

std::map<std::string, diagnostic_msgs::DiagnosticStatus> g_diagnostics;  // by hardware id
ros::Publisher g_fleet_pub;                   // /pickers/beliefs (latched)
picker_localisation::PickerBeliefArray g_fleet;

void diagnosticsCallback(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(g_mutex);
  for (const auto& s : msg->status)
    if (s.name.size() > 13 && s.name.compare(s.name.size() - 13, 13, ": nbs_planner") == 0)  // not ": inputs"
      g_diagnostics[s.hardware_id] = s;
}

void markerCallback(const visualization_msgs::MarkerArray::ConstPtr& m) {
  std::lock_guard<std::mutex> lock(g_mutex);
  for (const auto& mk : m->markers)
    if (mk.type == visualization_msgs::Marker::SPHERE_LIST && !mk.points.empty()) g_markers = true;
}

// Waits until done() or `seconds` of wall time (by default generous, for a loaded machine).
bool waitFor(const std::function<bool()>& done, double seconds = test_wait::kDeadline) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < end) {
    if (done()) return true;
    ros::WallDuration(0.05).sleep();
  }
  return done();
}

// The value of `key` in the last diagnostics status of `robot`'s planner ("" when there is none).
std::string diagnosticValue(const std::string& robot, const std::string& key) {
  std::lock_guard<std::mutex> lock(g_mutex);
  auto it = g_diagnostics.find(robot);
  if (it == g_diagnostics.end()) return std::string();
  for (const auto& kv : it->second.values)
    if (kv.key == key) return kv.value;
  return std::string();
}

// True when `robot` publishes a goal stamped after now within `seconds` (its planner is still planning).
bool plansAgain(const std::string& robot, double seconds = test_wait::kDeadline) {
  const ros::Time now = ros::Time::now();
  return waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(g_mutex);
        return g_goals.count(robot) && g_goals.at(robot).header.stamp > now;
      },
      seconds);
}

}  // namespace

TEST(NbsPlannerNode, GoalsCandidatesMarkersAndFleet) {
  ros::NodeHandle nh;
  const std::vector<std::string> robots{"robot_1", "robot_2", "robot_3"};
  std::vector<ros::Subscriber> subs;
  subs.push_back(nh.subscribe("/diagnostics", 20, diagnosticsCallback));
  subs.push_back(nh.subscribe("/robot_4/goal", 5, goalCallback));
  for (const std::string& r : robots) subs.push_back(nh.subscribe("/" + r + "/goal", 5, goalCallback));
  subs.push_back(nh.subscribe("/robot_1/nbs_candidates", 1, markerCallback));

  ASSERT_TRUE(waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(g_mutex);
        return g_goals.size() == 3 && g_markers;
      },
      60.0))
      << "goals received: " << g_goals.size() << ", markers: " << g_markers;
  // Goals keep coming every planning period; take fresh ones after the what-if has been used.
  ASSERT_TRUE(waitFor([] { return g_what_if_calls.load() > 0; })) << "the planner never called the what-if";
  // Two planning periods later, however slow the machine: every robot planned twice more.
  for (int round = 0; round < 2; ++round)
    for (const std::string& r : robots) ASSERT_TRUE(plansAgain(r)) << r << " stopped planning";
  std::map<std::string, picker_localisation::GoalNode> goals;
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    goals = g_goals;
  }
  for (const auto& [id, g] : goals) {
    EXPECT_TRUE(g_map->index(g.node).has_value()) << id << " goal " << g.node;
    EXPECT_EQ(g.header.frame_id, "map");
    EXPECT_GE(g.utility, 0.0);
    EXPECT_LE(g.utility, 1.0 + 1e-9);
  }
  // robot_1 (NBS) serves the uncertain picker_2: its goal is within the read range of picker_2's lane.
  const auto& g1 = goals.at("robot_1");
  EXPECT_EQ(g1.policy, "nbs");
  EXPECT_EQ(g1.target_picker, "picker_2");
  double nearest = 1e9;
  for (NodeIndex n : g_lane_b) nearest = std::min(nearest, g_map->distance(n, *g_map->index(g1.node)));
  EXPECT_LE(nearest, 3.0) << "robot_1 goal " << g1.node;
  // Fleet rule: robot_2 (same pose, lower priority) never takes robot_1's goal.
  EXPECT_NE(goals.at("robot_2").node, g1.node);
  // EstimatedNode: robot_3 goes to picker_2's MAP node.
  EXPECT_EQ(goals.at("robot_3").policy, "estimated_node");
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    EXPECT_EQ(goals.at("robot_3").node, g_map->node(g_filter->belief().map_node).name);
  }

  // The goal as a PoseStamped too (navigation stacks that take a pose): exactly a node's pose, map frame.
  auto pose =
      ros::topic::waitForMessage<geometry_msgs::PoseStamped>("/robot_1/goal_pose", nh, ros::Duration(60.0));
  ASSERT_TRUE(pose) << "no /robot_1/goal_pose";
  EXPECT_EQ(pose->header.frame_id, "map");
  const Eigen::Vector2d at(pose->pose.position.x, pose->pose.position.y);
  EXPECT_LT((g_map->position2d(g_map->nearestNode(at)) - at).norm(), 1e-9);

  // get_candidates: ranked, one normalised row of 4 criteria per node, all in [0, 1].
  ros::ServiceClient client = nh.serviceClient<picker_localisation::GetCandidates>("/robot_1/get_candidates");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(60.0)));
  picker_localisation::GetCandidates srv;
  srv.request.max_candidates = 0;
  ASSERT_TRUE(client.call(srv));
  ASSERT_EQ(srv.response.criteria.size(), 4u);
  EXPECT_EQ(srv.response.criteria[2], "rfid_gain");
  ASSERT_GT(srv.response.nodes.size(), 50u);  // every reachable node of the map but robot_2's claim at most
  ASSERT_EQ(srv.response.utilities.size(), srv.response.nodes.size());
  ASSERT_EQ(srv.response.normalised_criteria.size(), 4 * srv.response.nodes.size());
  for (std::size_t i = 1; i < srv.response.utilities.size(); ++i)
    EXPECT_GE(srv.response.utilities[i - 1], srv.response.utilities[i]);
  for (double v : srv.response.normalised_criteria) {
    EXPECT_GE(v, 0.0);
    EXPECT_LE(v, 1.0);
  }
  srv.request.max_candidates = 5;
  ASSERT_TRUE(client.call(srv));
  EXPECT_EQ(srv.response.nodes.size(), 5u);

  // Bad input: a belief of a map we do not have (unknown node names) for picker_3 is rejected, planning goes
  // on.
  picker_localisation::PickerBelief bad;
  bad.picker_id = "picker_3";
  bad.nodes = {"NoSuchNode", "NotThisOneEither"};
  bad.masses = {0.5, std::nan("")};
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_fleet.beliefs.push_back(bad);
    g_fleet_pub.publish(g_fleet);
  }
  ASSERT_TRUE(waitFor([] {
    const std::string rejected = diagnosticValue("robot_1", "beliefs rejected picker_3");
    return !rejected.empty() && rejected != "0";
  })) << "robot_1 diagnostics never counted the bad belief";
  ASSERT_TRUE(plansAgain("robot_1")) << "robot_1 stopped planning after a bad belief";

  // Missing tf: robot_4 publishes no goal and reports the missing pose.
  std::lock_guard<std::mutex> lock(g_mutex);
  EXPECT_EQ(g_goals.count("robot_4"), 0u);
  ASSERT_EQ(g_diagnostics.count("robot_4"), 1u);
  EXPECT_EQ(g_diagnostics.at("robot_4").level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_NE(g_diagnostics.at("robot_4").message.find("no robot pose"), std::string::npos)
      << g_diagnostics.at("robot_4").message;
}

// A stale pose: when the robot's localisation stops, tf keeps serving the last pose. robot_5 (max_pose_age 1
// s) plans while its pose is fresh, then stops planning and says why instead of sending the robot from where
// it was.
TEST(NbsPlannerNode, StaleRobotPoseStopsPlanning) {
  ros::NodeHandle nh;
  ros::Subscriber goals = nh.subscribe("/robot_5/goal", 5, goalCallback);
  ros::Subscriber diagnostics = nh.subscribe("/diagnostics", 20, diagnosticsCallback);
  tf2_ros::TransformBroadcaster tf;
  auto sendPose = [&] {
    geometry_msgs::TransformStamped t;
    t.header.stamp = ros::Time::now();
    t.header.frame_id = "map";
    t.child_frame_id = "robot_5/base_link";
    t.transform.translation.x = g_map->node(g_robot_node).position.x();
    t.transform.translation.y = g_map->node(g_robot_node).position.y();
    t.transform.rotation.w = 1.0;
    tf.sendTransform(t);
  };
  ASSERT_TRUE(waitFor(
      [&] {
        sendPose();
        ros::WallDuration(0.1).sleep();
        std::lock_guard<std::mutex> lock(g_mutex);
        return g_goals.count("robot_5") > 0;
      },
      30.0))
      << "robot_5 never planned with a fresh pose";
  const ros::Time stopped = ros::Time::now();  // the localisation stops here
  ASSERT_TRUE(waitFor([] {
    std::lock_guard<std::mutex> lock(g_mutex);
    auto it = g_diagnostics.find("robot_5");
    return it != g_diagnostics.end() && it->second.message.find("s old") != std::string::npos;
  })) << "robot_5 never reported its stale pose";
  ros::WallDuration(2.5).sleep();  // more than two planning periods after the report
  std::lock_guard<std::mutex> lock(g_mutex);
  EXPECT_LT(g_goals.at("robot_5").header.stamp.toSec(), stopped.toSec() + 1.5)
      << "robot_5 kept planning from a stale pose";
  EXPECT_EQ(g_diagnostics.at("robot_5").level, diagnostic_msgs::DiagnosticStatus::WARN);
  bool counted = false;
  for (const auto& kv : g_diagnostics.at("robot_5").values)
    if (kv.key == "stale robot poses") counted = kv.value != "0";
  EXPECT_TRUE(counted);
}

// The planner may only read beliefs, the picker list, goals, call goals, the battery, tf and the clock: never
// a ground-truth topic.
TEST(NbsPlannerNode, SubscribesToNoGroundTruthTopic) {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  ASSERT_TRUE(ros::master::execute("getSystemState", args, result, payload, true));
  const XmlRpc::XmlRpcValue& subscribers = payload[1];  // [[topic, [node, ...]], ...]
  std::map<std::string, std::set<std::string>> by_node;
  for (int i = 0; i < subscribers.size(); ++i) {
    XmlRpc::XmlRpcValue entry = subscribers[i];
    const std::string topic = entry[0];
    for (int j = 0; j < entry[1].size(); ++j) by_node[std::string(entry[1][j])].insert(topic);
  }
  std::size_t planners = 0;
  for (const auto& [node, topics] : by_node) {
    if (node.find("nbs_planner") == std::string::npos) continue;
    ++planners;
    // robot_3 reads each picker's topic (~belief_topic ""), the others the trackers' fleet stream.
    if (node.find("robot_3") != std::string::npos)
      EXPECT_TRUE(topics.count("/pickers/picker_1/belief")) << node;
    else
      EXPECT_TRUE(topics.count("/pickers/beliefs") && !topics.count("/pickers/picker_1/belief")) << node;
    for (const std::string& t : topics) {
      EXPECT_EQ(t.find("ground_truth"), std::string::npos) << node << " subscribes to " << t;
      const bool allowed =
          (t.rfind("/pickers/", 0) == 0 && t.size() > 7 && t.substr(t.size() - 7) == "/belief") ||
          t == "/pickers/beliefs" || t == "/pickers/registry" ||
          (t.size() > 5 && t.substr(t.size() - 5) == "/goal") ||
          (t.size() > 10 && t.substr(t.size() - 10) == "/call_goal") || t == "/tf" || t == "/tf_static" ||
          t == "/clock" || (t.size() > 8 && t.substr(t.size() - 8) == "/battery") ||
          (t == "/dispatcher/status" && node.find("robot_6") != std::string::npos);  // call_due_weight > 0
      EXPECT_TRUE(allowed) << node << " subscribes to " << t;
    }
    // Only a planner weighing pickers about to call reads the dispatcher's calls.
    EXPECT_EQ(topics.count("/dispatcher/status") == 1, node.find("robot_6") != std::string::npos) << node;
  }
  EXPECT_EQ(planners, 6u);
}

// A planner with call_due_weight > 0 reads the dispatcher's calls (when each picker's trays were emptied).
TEST(NbsPlannerNode, ReadsTheDispatchersCallsForCallDueWeights) {
  ros::NodeHandle nh;
  ros::Subscriber diag = nh.subscribe("/diagnostics", 20, diagnosticsCallback);
  ros::Publisher status = nh.advertise<picker_localisation::CallStatusArray>("/dispatcher/status", 1, true);
  picker_localisation::CallStatusArray calls;
  picker_localisation::CallStatus c;
  c.call_id = 1;
  c.picker_id = "picker_1";
  c.state = "queued";
  c.called = ros::Time::now();
  calls.calls.push_back(c);
  status.publish(calls);
  EXPECT_TRUE(waitFor([] {
    const std::string v = diagnosticValue("robot_6", "call status messages");
    return !v.empty() && std::stoul(v) >= 1;
  })) << "robot_6 did not count the dispatcher's status";
  const std::string weight = diagnosticValue("robot_6", "call-due weight");
  ASSERT_FALSE(weight.empty());
  EXPECT_DOUBLE_EQ(std::stod(weight), 4.0);
  EXPECT_TRUE(waitFor([] { return !diagnosticValue("robot_1", "call status messages").empty(); }));
  EXPECT_EQ(diagnosticValue("robot_1", "call status messages"), "0");  // call_due_weight 0: not subscribed
}

// A picker the tracker adds at run time (its latched list on /pickers/registry) is planned for: its beliefs on
// the fleet stream are counted; one the list dropped is no longer reported.
TEST(NbsPlannerNode, FollowsThePickerListOfTheTracker) {
  ros::NodeHandle nh;
  ros::Subscriber diag = nh.subscribe("/diagnostics", 20, diagnosticsCallback);
  ros::Publisher list_pub = nh.advertise<picker_localisation::PickerList>("/pickers/registry", 1, true);
  picker_localisation::PickerList list;
  for (const char* id : {"picker_1", "picker_2", "picker_9"}) {
    picker_localisation::PickerInfo info;
    info.id = id;
    list.pickers.push_back(info);
  }
  list_pub.publish(list);
  auto value = [](const std::string& robot, const std::string& key) -> std::string {
    std::lock_guard<std::mutex> lock(g_mutex);
    auto it = g_diagnostics.find(robot);
    if (it == g_diagnostics.end()) return "";
    for (const auto& kv : it->second.values)
      if (kv.key == key) return kv.value;
    return "";
  };
  ASSERT_TRUE(waitFor([&] { return value("robot_1", "beliefs received picker_9") == "0"; }))
      << "robot_1 never listed picker_9";
  EXPECT_EQ(value("robot_1", "beliefs received picker_3"), "") << "picker_3 left the list";
  // A new picker's first belief, "waiting for the first observation" (no nodes), is nothing to reject.
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    picker_localisation::PickerBelief waiting;
    waiting.header.stamp = ros::Time::now();
    waiting.picker_id = "picker_9";
    g_fleet.beliefs.push_back(waiting);
    g_fleet_pub.publish(g_fleet);
    g_fleet.beliefs.pop_back();
  }
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_fleet.beliefs.push_back(beliefMsg("picker_9", {g_confident_node}, {1.0}, g_confident_node));
    g_fleet_pub.publish(g_fleet);
  }
  EXPECT_TRUE(waitFor([&] { return value("robot_1", "beliefs received picker_9") == "1"; }))
      << "robot_1 counted " << value("robot_1", "beliefs received picker_9") << " beliefs of picker_9";
  EXPECT_EQ(value("robot_1", "beliefs rejected picker_9"), "0") << "the empty first belief was called bad";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_nbs_planner_node");
  ros::NodeHandle nh, pnh("~");
  std::string map_file;
  pnh.getParam("map_file", map_file);
  g_map = std::make_shared<const topology::TopologicalMap>(topology::loadMap(map_file));

  // Lanes: picker_1 confident in the first lane, picker_2 uncertain along the last lane, the robots on the
  // middle node of the lane next to the last one.
  const auto lane_a = g_map->laneNodes(0);
  g_lane_b = g_map->laneNodes(static_cast<topology::LaneIndex>(g_map->numLanes() - 1));
  const auto lane_c = g_map->laneNodes(static_cast<topology::LaneIndex>(g_map->numLanes() - 2));
  g_confident_node = lane_a[lane_a.size() / 2];
  g_robot_node = lane_c[lane_c.size() / 2];

  // picker_2's filter: one broad GNSS fix along the middle of lane B.
  g_filter = std::make_unique<tpf::TopologicalParticleFilter>(g_map, tpf::TpfParams(), 5);
  core::Observation fix;
  fix.stamp = 10.0;
  fix.sensor = "gnss";
  fix.picker_id = "picker_2";
  fix.identifying = true;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Identity() * 25.0;
  core::setGaussianLikelihood(fix, *g_map, g_map->position2d(g_lane_b[g_lane_b.size() / 2]), cov);
  g_filter->update(fix);

  ros::ServiceServer what_if = nh.advertiseService("/pickers/picker_2/what_if", whatIf);
  // Both ways a planner reads beliefs: the trackers' fleet stream and each picker's own latched topic.
  ros::Publisher b1 = nh.advertise<picker_localisation::PickerBelief>("/pickers/picker_1/belief", 1, true);
  ros::Publisher b2 = nh.advertise<picker_localisation::PickerBelief>("/pickers/picker_2/belief", 1, true);
  g_fleet_pub = nh.advertise<picker_localisation::PickerBeliefArray>("/pickers/beliefs", 1, true);
  g_fleet.beliefs = {beliefMsg("picker_1", {g_confident_node}, {1.0}, g_confident_node),
                     beliefMsg("picker_2", g_filter->belief())};
  b1.publish(g_fleet.beliefs[0]);
  b2.publish(g_fleet.beliefs[1]);
  g_fleet_pub.publish(g_fleet);

  tf2_ros::StaticTransformBroadcaster tf;
  std::vector<geometry_msgs::TransformStamped> transforms;
  for (const std::string& r : {"robot_1", "robot_2", "robot_3"}) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = ros::Time::now();
    t.header.frame_id = "map";
    t.child_frame_id = r + "/base_link";
    t.transform.translation.x = g_map->node(g_robot_node).position.x();
    t.transform.translation.y = g_map->node(g_robot_node).position.y();
    t.transform.rotation.w = 1.0;
    transforms.push_back(t);
  }
  tf.sendTransform(transforms);

  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int rc = RUN_ALL_TESTS();
  spinner.stop();
  return rc;
}
