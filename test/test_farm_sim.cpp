// rostest: farm_sim drives /clock, publishes tf per robot, every raw sensor topic and the pickers' ground
// truth, and drives a robot to a goal node sent on /<robot>/goal (unknown goals are ignored, the node keeps
// running).
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <picker_localisation/BearingDetectionArray.h>
#include <picker_localisation/GoalNode.h>
#include <picker_localisation/RfidReading.h>
#include <picker_localisation/UwbRange.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/NavSatFix.h>
#include <tf2_ros/transform_listener.h>

#include <map>
#include <mutex>

#include "diagnostics_rostest_util.h"
#include "picker_localisation/topology/map_io.h"

using namespace picker_localisation;

namespace {

struct Recorder {
  std::mutex mutex;
  std::map<std::string, int> counts;
  std::map<std::string, geometry_msgs::PoseStamped> last_pose;
  std::map<std::string, double> first_stamp;
  std::vector<ros::Subscriber> subs;
  sensor_msgs::LaserScan last_scan;
  sensor_msgs::NavSatFix last_fix;
  int valid_fixes = 0;

  template <class M>
  void count(ros::NodeHandle& nh, const std::string& topic) {
    subs.push_back(nh.subscribe<M>(topic, 100, [this, topic](const typename M::ConstPtr&) {
      std::lock_guard<std::mutex> l(mutex);
      ++counts[topic];
    }));
  }
  void pose(ros::NodeHandle& nh, const std::string& topic) {
    subs.push_back(nh.subscribe<geometry_msgs::PoseStamped>(
        topic, 100, [this, topic](const geometry_msgs::PoseStamped::ConstPtr& m) {
          std::lock_guard<std::mutex> l(mutex);
          ++counts[topic];
          last_pose[topic] = *m;
          first_stamp.emplace(topic, m->header.stamp.toSec());
        }));
  }
  int get(const std::string& topic) {
    std::lock_guard<std::mutex> l(mutex);
    return counts[topic];
  }
};

// Waits (wall time) until pred() or timeout (by default generous, for a loaded machine).
template <class P>
bool waitFor(P pred, double wall_timeout = test_wait::kDeadline) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(wall_timeout);
  while (ros::WallTime::now() < end) {
    if (pred()) return true;
    ros::WallDuration(0.02).sleep();
  }
  return pred();
}

}  // namespace

TEST(FarmSim, ClockTfTopicsGroundTruthAndGoals) {
  ros::NodeHandle nh, pnh("~");
  std::string map_file;
  ASSERT_TRUE(pnh.getParam("map_file", map_file));
  const auto map = topology::loadMap(map_file);
  ros::AsyncSpinner spinner(2);
  spinner.start();

  Recorder rec;
  rec.count<sensor_msgs::LaserScan>(nh, "/robot_1/scan_front");
  rec.count<sensor_msgs::LaserScan>(nh, "/robot_1/scan_rear");
  rec.count<picker_localisation::RfidReading>(nh, "/robot_1/rfid");
  rec.count<picker_localisation::UwbRange>(nh, "/robot_1/uwb");
  rec.count<picker_localisation::BearingDetectionArray>(nh, "/robot_1/camera/detections");
  for (const char* p : {"picker_1", "picker_2", "picker_3"}) {
    rec.count<sensor_msgs::NavSatFix>(nh, std::string("/pickers/") + p + "/fix");
    rec.pose(nh, std::string("/pickers/") + p + "/ground_truth");
  }
  rec.pose(nh, "/robot_1/ground_truth");

  // /clock advances.
  ASSERT_TRUE(waitFor([] { return ros::Time::now().toSec() > 0.0; }, 30.0)) << "no /clock";
  const ros::Time t0 = ros::Time::now();
  ASSERT_TRUE(waitFor([&] { return (ros::Time::now() - t0).toSec() > 10.0; }, 30.0))
      << "/clock does not advance";
  const ros::Time t1 = ros::Time::now();

  // The clock waited at start_time (100 s) for start_delay (farm_sim.test: 5 wall s), so this node,
  // subscribed by then, got the simulation from its first messages (ground truth at 10 Hz: 100.1 s).
  {
    std::lock_guard<std::mutex> l(rec.mutex);
    ASSERT_TRUE(rec.first_stamp.count("/robot_1/ground_truth"));
    EXPECT_LE(rec.first_stamp["/robot_1/ground_truth"], 100.25);
  }

  // Every topic published at roughly its simulated rate during those 10 s.
  EXPECT_GE(rec.get("/robot_1/scan_front"), 60);  // 10 Hz
  EXPECT_GE(rec.get("/robot_1/scan_rear"), 60);
  EXPECT_GE(rec.get("/robot_1/uwb"), 1);
  EXPECT_GE(rec.get("/robot_1/camera/detections"), 30);  // 5 Hz x 2 cameras, empty arrays included
  for (const char* p : {"picker_1", "picker_2", "picker_3"}) {
    EXPECT_GE(rec.get(std::string("/pickers/") + p + "/fix"), 6);  // 1 Hz (NO_FIX in blackouts included)
    EXPECT_GE(rec.get(std::string("/pickers/") + p + "/ground_truth"), 60);
  }

  // tf: map -> robot_1/odom -> robot_1/base_link matches the robot's ground truth; sensor frames exist.
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  ASSERT_TRUE(waitFor([&] { return buffer.canTransform("map", "robot_1/base_link", ros::Time(0)); }));
  for (const char* f : {"robot_1/laser_front", "robot_1/laser_rear", "robot_1/uwb_anchor_1",
                        "robot_1/camera_1", "robot_1/rfid_left"})
    EXPECT_TRUE(waitFor([&] { return buffer.canTransform("robot_1/base_link", f, ros::Time(0)); })) << f;
  const auto laser = buffer.lookupTransform("robot_1/base_link", "robot_1/laser_front", ros::Time(0));
  EXPECT_NEAR(laser.transform.translation.x, 0.78, 1e-6);
  EXPECT_NEAR(laser.transform.translation.y, 0.73, 1e-6);

  // Ground truth pickers are on the map (within an edge length of a node).
  {
    std::lock_guard<std::mutex> l(rec.mutex);
    for (const char* p : {"picker_1", "picker_2", "picker_3"}) {
      const auto& m = rec.last_pose[std::string("/pickers/") + p + "/ground_truth"];
      EXPECT_EQ(m.header.frame_id, "map");
      const Eigen::Vector2d pos(m.pose.position.x, m.pose.position.y);
      EXPECT_LT((map.position2d(map.nearestNode(pos)) - pos).norm(), 3.5) << p;
    }
  }

  // A bad goal is ignored; a good goal drives the robot there (patrol: stay, speed 1 m/s).
  ros::Publisher goal_pub = nh.advertise<picker_localisation::GoalNode>("/robot_1/goal", 1, true);
  picker_localisation::GoalNode bad;
  bad.robot_id = "robot_1";
  bad.node = "NoSuchNode";
  ASSERT_TRUE(waitFor([&] { return goal_pub.getNumSubscribers() > 0; }));
  goal_pub.publish(bad);
  ros::WallDuration(0.5).sleep();
  Eigen::Vector2d robot_pos;
  {
    std::lock_guard<std::mutex> l(rec.mutex);
    const auto& m = rec.last_pose["/robot_1/ground_truth"];
    robot_pos = {m.pose.position.x, m.pose.position.y};
  }
  const topology::NodeIndex start = map.nearestNode(robot_pos);
  const topology::NodeIndex goal = *map.index("WayPoint1");
  ASSERT_NE(start, goal);
  const double travel = map.pathLength(start, goal);
  picker_localisation::GoalNode good;
  good.robot_id = "robot_1";
  good.node = "WayPoint1";
  goal_pub.publish(good);
  const ros::Time sent = ros::Time::now();
  // The default (generous) deadline: the simulation runs slower on a loaded machine.
  const bool arrived = waitFor([&] {
    std::lock_guard<std::mutex> l(rec.mutex);
    const auto& m = rec.last_pose["/robot_1/ground_truth"];
    return (Eigen::Vector2d(m.pose.position.x, m.pose.position.y) - map.position2d(goal)).norm() < 0.05;
  });
  EXPECT_TRUE(arrived);
  // It took about the path length at 1 m/s of simulated time (not less).
  EXPECT_GE((ros::Time::now() - sent).toSec(), travel - 1.0);
  EXPECT_GT((t1 - t0).toSec(), 9.9);
}

TEST(FarmSim, PublishesDiagnostics) {
  ros::NodeHandle nh;
  const auto seen = diagnostics_test::collect(nh, {"/farm_sim"});
  ASSERT_TRUE(seen.count("/farm_sim"));
  EXPECT_TRUE(seen.at("/farm_sim").count("simulation"));
  EXPECT_TRUE(seen.at("/farm_sim").count("inputs"));  // goals
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_farm_sim");
  return RUN_ALL_TESTS();
}
