#include "picker_localisation/ros/node_diagnostics.h"

#include <algorithm>
#include <cstdio>

namespace picker_localisation {
namespace ros_adapter {

void InputRate::tick() {
  std::lock_guard<std::mutex> lock(mutex_);
  ++total_;
  last_ = ros::Time::now().toSec();
}

std::string InputRate::report(diagnostic_updater::DiagnosticStatusWrapper& stat, double now, double window) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!history_.empty() && now < history_.back().first) history_.clear();  // the clock went back
  if (last_ > now) last_ = now;
  history_.emplace_back(now, total_);
  while (history_.size() > 2 && history_[1].first <= now - window) history_.pop_front();
  const double span = now - history_.front().first;
  char rate[32] = "-";
  if (span > 0.0)
    std::snprintf(rate, sizeof(rate), "%.2f", static_cast<double>(total_ - history_.front().second) / span);
  char age[32] = "never";
  if (last_ >= 0.0) std::snprintf(age, sizeof(age), "%.1f", now - last_);
  stat.add(name_ + " received / rate [Hz] / newest [s ago]",
           std::to_string(total_) + " / " + rate + " / " + age);
  if (stale_after_ > 0.0 && last_ >= 0.0 && now - last_ > stale_after_)
    return name_ + ": nothing for " + age + " s";
  return "";
}

InputRate& NodeDiagnostics::input(const std::string& name, double stale_after) {
  std::lock_guard<std::mutex> lock(inputs_mutex_);
  for (const auto& in : inputs_)
    if (in->name() == name) return *in;
  if (inputs_.empty()) updater_.add("inputs", this, &NodeDiagnostics::reportInputs);
  inputs_.push_back(std::make_unique<InputRate>(name, stale_after));
  return *inputs_.back();
}

void NodeDiagnostics::tick(const std::string& name) {
  input(name).tick();
}

void NodeDiagnostics::reportInputs(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const double now = ros::Time::now().toSec();
  std::string warnings;
  std::lock_guard<std::mutex> lock(inputs_mutex_);
  for (const auto& in : inputs_) {
    const std::string w = in->report(stat, now, window_);
    if (!w.empty()) warnings += (warnings.empty() ? "" : "; ") + w;
  }
  if (warnings.empty())
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "inputs flowing or not expected yet");
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, warnings);
}

void NodeDiagnostics::start(ros::NodeHandle& nh, double period, bool wall) {
  if (wall)
    wall_timer_ =
        nh.createWallTimer(ros::WallDuration(period), [this](const ros::WallTimerEvent&) { publish(); });
  else
    timer_ = nh.createTimer(ros::Duration(period), [this](const ros::TimerEvent&) { publish(); });
}

void NodeDiagnostics::publish() {
  const double now = ros::Time::now().toSec();
  if (now < last_publish_)
    updater_.force_update();
  else
    updater_.update();
  last_publish_ = now;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
