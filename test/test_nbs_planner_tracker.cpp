// rostest: nbs_planner plans with the real tpf_tracker's what-if service (no fallback) and serves the picker
// whose tracker holds a belief. The test only feeds the tracker an observation and publishes a static tf.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <picker_localisation/GoalNode.h>
#include <picker_localisation/Observation.h>

#include <map>
#include <mutex>

#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/topology/map_io.h"

using namespace picker_localisation;

namespace {
std::mutex g_mutex;
std::optional<picker_localisation::GoalNode> g_goal;
std::map<std::string, std::string> g_planner_diag;

void goalCallback(const picker_localisation::GoalNode::ConstPtr& m) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_goal = *m;
}
void diagCallback(const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
  std::lock_guard<std::mutex> lock(g_mutex);
  for (const auto& s : m->status)
    if (s.name.find("nbs_planner") != std::string::npos)
      for (const auto& kv : s.values) g_planner_diag[kv.key] = kv.value;
}
}  // namespace

TEST(NbsPlannerTracker, PlansWithTheTrackersWhatIf) {
  ros::NodeHandle nh, pnh("~");
  std::string map_file;
  pnh.getParam("map_file", map_file);
  const topology::TopologicalMap map = topology::loadMap(map_file);
  const auto lane = map.laneNodes(static_cast<topology::LaneIndex>(map.numLanes() - 1));
  const topology::NodeIndex picker_node = lane[lane.size() / 2];
  const auto robot_lane = map.laneNodes(static_cast<topology::LaneIndex>(map.numLanes() - 2));

  tf2_ros::StaticTransformBroadcaster tf;
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = "map";
  t.child_frame_id = "robot_1/base_link";
  t.transform.translation.x = map.node(robot_lane[robot_lane.size() / 2]).position.x();
  t.transform.translation.y = map.node(robot_lane[robot_lane.size() / 2]).position.y();
  t.transform.rotation.w = 1.0;
  tf.sendTransform(t);

  ros::Subscriber goal_sub = nh.subscribe("/robot_1/goal", 5, goalCallback);
  ros::Subscriber diag_sub = nh.subscribe("/diagnostics", 20, diagCallback);
  ros::Publisher obs_pub = nh.advertise<picker_localisation::Observation>("/observations", 10);
  ros::AsyncSpinner spinner(2);
  spinner.start();

  // A broad GNSS-like observation of picker_2 in the last lane, repeated (the tracker may subscribe late).
  core::Observation obs;
  obs.sensor = "gnss";
  obs.picker_id = "picker_2";
  obs.identifying = true;
  core::setGaussianLikelihood(obs, map, map.position2d(picker_node), Eigen::Matrix2d::Identity() * 16.0);
  bool done = false;
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(45.0);
  while (ros::ok() && ros::WallTime::now() < end && !done) {
    obs.stamp = ros::Time::now().toSec();
    picker_localisation::Observation msg = ros_adapter::toMsg(obs, map);
    msg.header.stamp = ros::Time::now();
    obs_pub.publish(msg);
    ros::WallDuration(0.5).sleep();
    std::lock_guard<std::mutex> lock(g_mutex);
    done = g_goal && g_goal->target_picker == "picker_2" && g_planner_diag.count("what-if queries") &&
           g_planner_diag["what-if queries"] != "0";
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  ASSERT_TRUE(g_goal.has_value()) << "no goal from nbs_planner";
  EXPECT_EQ(g_goal->target_picker, "picker_2");
  ASSERT_TRUE(g_planner_diag.count("what-if queries"));
  EXPECT_NE(g_planner_diag["what-if queries"], "0");
  EXPECT_EQ(g_planner_diag["plans on the fallback belief (no what-if)"], "0");
  // The goal is within the read range (3 m) of the picker's lane.
  double nearest = 1e9;
  for (topology::NodeIndex n : lane) nearest = std::min(nearest, map.distance(n, *map.index(g_goal->node)));
  EXPECT_LE(nearest, 3.0) << g_goal->node;
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_nbs_planner_tracker");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
