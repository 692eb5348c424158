// rostest: tpf_tracker's periodic prediction runs on ROS time. The test drives /clock: while the simulated
// clock stands still nothing is predicted however long the wall clock runs; advancing /clock by 10 s yields
// predictions stamped on the simulated clock (every 1 / prediction_rate = 2 s), none beyond it.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>

#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBelief.h>

#include <memory>

#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/topology/map_io.h"
#include "wait_deadline.h"

using namespace picker_localisation;

TEST(TrackerSimTime, PeriodicPredictionFollowsTheSimulatedClock) {
  ros::NodeHandle nh;
  auto map = topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
  ros::Publisher clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10, true);
  ros::Publisher obs_pub = nh.advertise<picker_localisation::Observation>("/observations", 10);
  std::vector<PickerBelief> beliefs;
  ros::Subscriber sub = nh.subscribe<PickerBelief>(
      "/pickers/picker_sim/belief", 50, [&](const PickerBelief::ConstPtr& m) { beliefs.push_back(*m); });
  auto setClock = [&](double t) {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(t);
    clock.publish(c);
  };
  auto spinWall = [&](double seconds) {
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::WallTime::now() < until) {
      ros::spinOnce();
      ros::WallDuration(0.01).sleep();
    }
  };
  // Spins until done() or 60 s of wall time (generous, for a loaded machine); returns done().
  auto waitWall = [&](auto done) {
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(test_wait::kDeadline);
    while (!done() && ros::WallTime::now() < until) {
      ros::spinOnce();
      ros::WallDuration(0.01).sleep();
    }
    return done();
  };
  setClock(100.0);
  ASSERT_TRUE(ros::service::waitForService("/pickers/picker_sim/what_if", ros::Duration(30.0)));
  const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(test_wait::kDeadline);
  while (obs_pub.getNumSubscribers() == 0 && ros::WallTime::now() < until) ros::WallDuration(0.05).sleep();
  ASSERT_GT(obs_pub.getNumSubscribers(), 0u);

  core::Observation o;
  o.stamp = 100.0;
  o.sensor = "gnss";
  o.identifying = true;
  o.picker_id = "picker_sim";
  core::setGaussianLikelihood(o, map, map.position2d(map.laneNodes(0).front()), Eigen::Matrix2d::Identity());
  obs_pub.publish(ros_adapter::toMsg(o, map));
  ASSERT_TRUE(waitWall([&] { return !beliefs.empty() && beliefs.back().observations == 1; }));
  EXPECT_DOUBLE_EQ(beliefs.back().header.stamp.toSec(), 100.0);

  // Simulated clock stopped: 3 s of wall time bring no prediction.
  const std::size_t before = beliefs.size();
  spinWall(3.0);
  EXPECT_EQ(beliefs.size(), before);

  // Simulated clock runs 100 -> 110 s in 0.1 s steps: predictions stamped in (100, 110], about every 2 s.
  for (int k = 1; k <= 100; ++k) {
    setClock(100.0 + 0.1 * k);
    spinWall(0.02);
  }
  // The predictions up to the clock's last step, however slow the machine; then none beyond it.
  waitWall([&] { return beliefs.size() > before + 2 && beliefs.back().header.stamp.toSec() >= 107.0; });
  spinWall(0.5);
  ASSERT_GT(beliefs.size(), before + 2);
  for (std::size_t k = before; k < beliefs.size(); ++k) {
    EXPECT_GT(beliefs[k].header.stamp.toSec(), 100.0);
    EXPECT_LE(beliefs[k].header.stamp.toSec(), 110.0 + 1e-6);
    EXPECT_EQ(beliefs[k].observations, 1u);  // predictions only
  }
  EXPECT_LE(beliefs.size() - before, 6u);  // every 2 s of simulated time, not of wall time
  EXPECT_GE(beliefs.back().header.stamp.toSec(), 107.0);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_tpf_tracker_sim_time");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
