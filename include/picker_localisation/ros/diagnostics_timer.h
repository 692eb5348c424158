// Publishes a node's diagnostic_updater::Updater every `period` s of ROS time (the Updater publishes only when
// update() is called: leg_detector and camera_detector once never called it). Updater::update() also waits until
// the clock passes its next publication time, so after the clock jumped back (a looped bag, a restarted
// simulator) a node fell silent on /diagnostics for as long as the jump, a whole loop of a looped bag. Here a
// jump back publishes at once and re-arms the updater on the new time line.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

namespace picker_localisation {
namespace ros_adapter {

class DiagnosticsTimer {
 public:
  // `wall`: a wall-clock timer (reports even while a simulated clock is paused: the map server).
  void start(ros::NodeHandle& nh, diagnostic_updater::Updater& updater, double period = 1.0, bool wall = false) {
    updater_ = &updater;
    if (wall)
      wall_timer_ = nh.createWallTimer(ros::WallDuration(period), [this](const ros::WallTimerEvent&) { publish(); });
    else
      timer_ = nh.createTimer(ros::Duration(period), [this](const ros::TimerEvent&) { publish(); });
  }
  // update(), or force_update() when the clock went back since the last call.
  void publish() {
    if (!updater_) return;
    const double now = ros::Time::now().toSec();
    if (now < last_) updater_->force_update();
    else updater_->update();
    last_ = now;
  }

 private:
  diagnostic_updater::Updater* updater_ = nullptr;
  ros::Timer timer_;
  ros::WallTimer wall_timer_;
  double last_ = 0.0;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
