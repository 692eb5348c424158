// Shared helper of the sensors_vision rostests.
#pragma once

#include <ros/ros.h>

#include <functional>

#include "wait_deadline.h"

namespace vision_test {

using test_wait::kDeadline;

// Spins until done() holds or `seconds` of wall time have passed; returns done().
inline bool waitFor(const std::function<bool()>& done, double seconds = kDeadline) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < end) {
    ros::spinOnce();
    if (done()) return true;
    ros::WallDuration(0.01).sleep();
  }
  return done();
}

}  // namespace vision_test
