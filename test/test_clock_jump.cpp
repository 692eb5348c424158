// rostest: /clock runs 100 -> 112 s with a fix per second, then jumps back to 10 s and runs on with fixes
// stamped 10.. s. Before clock jumps were handled gnss_ingest rejected every later fix as "not after the last
// accepted one" and the tracker dropped every observation as too old, so beliefs stopped; now both reset once
// and beliefs stamped after the jump appear.
#include <gtest/gtest.h>
#include <geometry_msgs/PoseStamped.h>
#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/TrackingError.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/NavSatFix.h>

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "ranging_rostest_util.h"

using ranging_test::waitFor;

TEST(ClockJump, BeliefsContinueAfterTheClockJumpsBack) {
  ros::NodeHandle nh;
  ros::Publisher clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  ros::Publisher fix = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_1/fix", 10);
  std::vector<double> belief_stamps;
  ros::Subscriber sub = nh.subscribe<picker_localisation::PickerBelief>(
      "/pickers/picker_1/belief", 100,
      [&](const picker_localisation::PickerBelief::ConstPtr& m) { belief_stamps.push_back(m->header.stamp.toSec()); });
  ros::Publisher truth = nh.advertise<geometry_msgs::PoseStamped>("/pickers/picker_1/ground_truth", 10);
  std::vector<double> error_stamps;
  ros::Subscriber error_sub = nh.subscribe<picker_localisation::TrackingError>(
      "/pickers/picker_1/error", 100,
      [&](const picker_localisation::TrackingError::ConstPtr& m) { error_stamps.push_back(m->header.stamp.toSec()); });
  ASSERT_TRUE(waitFor([&] { return fix.getNumSubscribers() > 0 && sub.getNumPublishers() > 0 &&
                                    clock.getNumSubscribers() >= 3 && truth.getNumSubscribers() > 0 &&
                                    error_sub.getNumPublishers() > 0; }, 30.0));
  const auto datum = picker_localisation::core::GeodeticDatum::load(std::string(PL_PACKAGE_DIR) +
                                                                         "/config/datum.yaml");
  auto run = [&](double t0, double t1) {
    for (double t = t0; t <= t1 + 1e-9; t += 0.1) {
      rosgraph_msgs::Clock c;
      c.clock = ros::Time(t);
      clock.publish(c);
      if (std::abs(t - std::round(t)) < 1e-6) {  // one fix per second, walking along a Riseholme lane
        const Eigen::Vector2d at(16.0, -30.0 + 0.5 * (t - t0));
        fix.publish(ranging_test::fixAt(datum, at, ros::Time(t)));
        geometry_msgs::PoseStamped p;
        p.header.stamp = ros::Time(t);
        p.header.frame_id = "map";
        p.pose.position.x = at.x();
        p.pose.position.y = at.y();
        p.pose.orientation.w = 1.0;
        truth.publish(p);
      }
      waitFor([] { return false; }, 0.02);
    }
  };
  run(100.0, 112.0);
  ASSERT_TRUE(waitFor([&] { return !belief_stamps.empty() && belief_stamps.back() >= 105.0; }))
      << belief_stamps.size() << " beliefs before the jump";
  const std::size_t before = belief_stamps.size();
  run(10.0, 25.0);  // the clock jumped back by 102 s
  std::size_t after_jump = 0, errors_after = 0;
  auto count = [&] {
    after_jump = errors_after = 0;
    for (std::size_t i = before; i < belief_stamps.size(); ++i)
      after_jump += (belief_stamps[i] >= 11.0 && belief_stamps[i] <= 26.0) ? 1 : 0;
    for (double s : error_stamps) errors_after += (s >= 11.0 && s <= 26.0) ? 1 : 0;
    return after_jump >= 5 && belief_stamps.back() >= 15.0 && errors_after >= 5;
  };
  waitFor(count);  // the new time line's beliefs and error samples, however slow the machine
  EXPECT_GE(after_jump, 5u) << "beliefs stamped after the jump back: " << after_jump;
  EXPECT_GE(belief_stamps.back(), 15.0);
  EXPECT_LE(belief_stamps.back(), 26.0);
  // The evaluator samples the new time line too (before clock jumps were handled its next sample lay 100 s
  // ahead).
  EXPECT_GE(errors_after, 5u) << error_stamps.size() << " error samples, " << errors_after << " after the jump";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_clock_jump");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
