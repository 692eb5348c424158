// The diagnostics of a node: one diagnostic_updater::Updater, the timer that publishes it, and the rate of
// each of the node's inputs. Every node of the package uses it, so every node reports on /diagnostics the
// same way.
//
// Publishing: the Updater publishes only when update() is called (leg_detector and camera_detector once never
// called it). Updater::update() also waits until the clock passes its next publication time, so after the
// clock jumped back (a looped bag, a restarted simulator) a node fell silent on /diagnostics for as long as
// the jump, a whole loop of a looped bag: here a jump back publishes at once and re-arms the updater on the
// new time line.
//
// Inputs: input("scans", 2.0) declares one, tick("scans") counts a message from the callback. One status
// "<node>: inputs" lists per input the messages received, the rate over the last `window` s and the age of
// the newest; an input declared with stale_after > 0 (a sensor stream) is WARN when it had messages and none
// came for that long.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace picker_localisation {
namespace ros_adapter {

// Messages of one input, counted from the node's callbacks (thread-safe).
class InputRate {
 public:
  InputRate(std::string name, double stale_after) : name_(std::move(name)), stale_after_(stale_after) {}
  void tick();
  const std::string& name() const { return name_; }
  // Adds this input's values to `stat`; returns a warning ("" when fine) at time `now`.
  std::string report(diagnostic_updater::DiagnosticStatusWrapper& stat, double now, double window);

 private:
  std::string name_;
  double stale_after_ = 0.0;
  std::mutex mutex_;
  unsigned long total_ = 0;
  double last_ = -1.0;                                    // s, ROS time of the newest message (-1: none yet)
  std::deque<std::pair<double, unsigned long>> history_;  // (time, total) at each report, the last window s
};

class NodeDiagnostics {
 public:
  NodeDiagnostics(ros::NodeHandle nh = ros::NodeHandle(), ros::NodeHandle pnh = ros::NodeHandle("~"))
      : updater_(nh, pnh) {}

  void setHardwareID(const std::string& id) { updater_.setHardwareID(id); }
  template <class T>
  void add(const std::string& name, T* owner, void (T::*run)(diagnostic_updater::DiagnosticStatusWrapper&)) {
    updater_.add(name, owner, run);
  }
  void add(const std::string& name, std::function<void(diagnostic_updater::DiagnosticStatusWrapper&)> run) {
    updater_.add(name, std::move(run));
  }
  bool removeByName(const std::string& name) { return updater_.removeByName(name); }

  // Declares an input (the "inputs" status appears with the first one); the reference stays valid.
  InputRate& input(const std::string& name, double stale_after = 0.0);
  // Counts one message of the input `name` (declared on first use with stale_after 0).
  void tick(const std::string& name);

  // Publishes every `period` s of ROS time (`wall`: of wall time, so a paused simulated clock does not
  // silence the node: the map server).
  void start(ros::NodeHandle& nh, double period = 1.0, bool wall = false);
  // update(), or force_update() when the clock went back since the last call (the timer calls it).
  void publish();

 private:
  void reportInputs(diagnostic_updater::DiagnosticStatusWrapper& stat);

  diagnostic_updater::Updater updater_;
  std::mutex inputs_mutex_;
  std::vector<std::unique_ptr<InputRate>> inputs_;
  double window_ = 10.0;  // s
  ros::Timer timer_;
  ros::WallTimer wall_timer_;
  double last_publish_ = 0.0;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
