// rostest: a call through the live graph (test/dispatcher_graph.test). farm_sim's pickers call on their own;
// the test only listens: each call's states as /dispatcher/status shows them, and the ground truth of pickers
// and robots, to check that an arrival was sensed close to the picker (not declared at a node) and that no
// robot served two open calls at once.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <geometry_msgs/PoseStamped.h>
#include <picker_localisation/CallStatusArray.h>

#include <Eigen/Core>
#include <map>
#include <mutex>
#include <vector>

#include "wait_deadline.h"

namespace {

std::mutex g_mutex;
std::map<std::uint64_t, std::vector<std::string>> g_states;  // per call, its states in the order first seen
std::map<std::uint64_t, picker_localisation::CallStatus> g_last;
std::map<std::uint64_t, double> g_arrival_distance;  // true robot-picker distance when first seen arrived
std::map<std::string, Eigen::Vector2d> g_truth;      // picker or robot id -> true position
bool g_shared_robot = false;

void statusCallback(const picker_localisation::CallStatusArray::ConstPtr& m) {
  std::lock_guard<std::mutex> lock(g_mutex);
  std::map<std::string, int> serving;
  for (const auto& c : m->calls) {
    auto& seen = g_states[c.call_id];
    if (seen.empty() || seen.back() != c.state) seen.push_back(c.state);
    g_last[c.call_id] = c;
    if (c.state == "arrived" && !g_arrival_distance.count(c.call_id) && g_truth.count(c.picker_id) &&
        g_truth.count(c.robot_id))
      g_arrival_distance[c.call_id] = (g_truth[c.picker_id] - g_truth[c.robot_id]).norm();
    if (!c.robot_id.empty() && c.state != "done" && c.state != "cancelled" && ++serving[c.robot_id] > 1)
      g_shared_robot = true;
  }
}

}  // namespace

TEST(DispatcherGraph, ACallGoesFromQueuedToDoneOnSensedArrival) {
  ros::NodeHandle nh;
  std::vector<ros::Subscriber> subs;
  subs.push_back(nh.subscribe("/dispatcher/status", 100, statusCallback));
  for (const std::string id : {"picker_1", "picker_2", "picker_3", "robot_1", "robot_2"}) {
    const std::string topic = (id.rfind("picker", 0) == 0 ? "/pickers/" : "/") + id + "/ground_truth";
    subs.push_back(nh.subscribe<geometry_msgs::PoseStamped>(
        topic, 20, [id](const geometry_msgs::PoseStamped::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(g_mutex);
          g_truth[id] = Eigen::Vector2d(m->pose.position.x, m->pose.position.y);
        }));
  }
  ros::AsyncSpinner spinner(2);
  spinner.start();
  // Generous: trays (20-60 s simulated), the drive, loading (15 s), the drive to storage, at 4x.
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(5 * test_wait::kDeadline);
  std::uint64_t done_call = 0;
  while (ros::ok() && ros::WallTime::now() < end && done_call == 0) {
    ros::WallDuration(0.2).sleep();
    std::lock_guard<std::mutex> lock(g_mutex);
    for (const auto& [id, c] : g_last)
      if (c.state == "done") done_call = id;
  }
  ASSERT_NE(done_call, 0u) << "no call reached done";
  std::lock_guard<std::mutex> lock(g_mutex);
  const std::vector<std::string> order{"queued", "assigned", "on_the_way", "arrived", "to_storage", "done"};
  const std::vector<std::string>& seen = g_states[done_call];
  std::string joined;
  for (const auto& s : seen) joined += s + " ";
  // Every state in order; each shows at least once (the status goes out at every change). A robot the planner
  // had already put beside the caller may sense it before the update that marks the call on its way: then the
  // call goes from assigned straight to arrived, and only then.
  std::vector<std::string> without_on_the_way = order;
  without_on_the_way.erase(without_on_the_way.begin() + 2);
  const auto& last = g_last[done_call];
  const bool arrived_at_once =
      (last.arrived - last.assigned).toSec() <= 1.5;  // within one update (1 s) or so
  if (seen == without_on_the_way)
    EXPECT_TRUE(arrived_at_once) << "on_the_way skipped though the arrival came "
                                 << (last.arrived - last.assigned).toSec() << " s after the assignment";
  else
    EXPECT_EQ(seen, order) << joined;
  const auto& c = g_last[done_call];
  EXPECT_FALSE(c.robot_id.empty());
  EXPECT_LE(c.called.toSec(), c.assigned.toSec());
  EXPECT_LE(c.assigned.toSec(), c.arrived.toSec());  // equal: sensed in the update that assigned it
  EXPECT_LT(c.arrived.toSec(), c.done.toSec());
  ASSERT_TRUE(g_arrival_distance.count(done_call));
  EXPECT_LE(g_arrival_distance[done_call], 3.0)
      << "arrival declared with the picker " << g_arrival_distance[done_call] << " m away";
  EXPECT_FALSE(g_shared_robot) << "one robot served two open calls";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_dispatcher_graph");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
