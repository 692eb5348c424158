#include "picker_localisation/ros/observation_conversions.h"

#include <cmath>
#include <limits>

namespace picker_localisation {
namespace ros_adapter {

ros::Time rosStamp(double seconds) {
  return ros::Time(std::isfinite(seconds) && seconds > 0.0 ? seconds : 0.0);
}

BeliefSupport beliefSupport(const picker_localisation::PickerBelief& msg,
                            const topology::TopologicalMap& map) {
  BeliefSupport support;
  for (std::size_t k = 0; k < msg.nodes.size() && k < msg.masses.size(); ++k) {
    const auto n = map.index(msg.nodes[k]);
    if (!n || !std::isfinite(msg.masses[k]) || msg.masses[k] < 0.0) continue;
    support.nodes.push_back(*n);
    support.masses.push_back(msg.masses[k]);
  }
  return support;
}

picker_localisation::Observation toMsg(const core::Observation& obs, const topology::TopologicalMap& map,
                                       const std::string& frame_id) {
  picker_localisation::Observation msg;
  msg.header.stamp = ros::Time(std::max(0.0, obs.stamp));
  msg.header.frame_id = frame_id;
  msg.sensor = obs.sensor;
  msg.robot_id = obs.robot_id;
  msg.picker_id = obs.picker_id;
  msg.identifying = obs.identifying;
  msg.candidate_pickers = obs.candidate_pickers;
  msg.candidate_probabilities = obs.candidate_probabilities;
  msg.nodes.reserve(obs.nodes.size());
  for (topology::NodeIndex n : obs.nodes) msg.nodes.push_back(map.node(n).name);
  msg.likelihood = obs.likelihood;
  msg.has_velocity = obs.velocity.has_value();
  if (obs.velocity) {
    msg.velocity.x = obs.velocity->x();
    msg.velocity.y = obs.velocity->y();
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  msg.position.x = obs.position ? obs.position->x() : nan;
  msg.position.y = obs.position ? obs.position->y() : nan;
  msg.position.z = obs.position ? 0.0 : nan;
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 2; ++c)
      msg.position_covariance[static_cast<std::size_t>(r * 3 + c)] = obs.position_covariance(r, c);
  msg.has_bias = obs.bias_removed.has_value();
  if (obs.bias_removed) {
    msg.bias_removed.x = obs.bias_removed->x();
    msg.bias_removed.y = obs.bias_removed->y();
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c)
        msg.bias_covariance[static_cast<std::size_t>(r * 2 + c)] = obs.bias_covariance(r, c);
    msg.bias_drift_rate = obs.bias_drift_rate;
  }
  return msg;
}

core::Observation fromMsg(const picker_localisation::Observation& msg, const topology::TopologicalMap& map,
                          std::size_t* unknown_nodes) {
  core::Observation obs;
  obs.stamp = msg.header.stamp.toSec();
  obs.sensor = msg.sensor;
  obs.robot_id = msg.robot_id;
  obs.picker_id = msg.picker_id;
  obs.identifying = msg.identifying;
  obs.candidate_pickers = msg.candidate_pickers;
  obs.candidate_probabilities = msg.candidate_probabilities;
  std::size_t unknown = 0;
  const std::size_t n = std::min(msg.nodes.size(), msg.likelihood.size());
  for (std::size_t i = 0; i < n; ++i) {
    auto idx = map.index(msg.nodes[i]);
    if (!idx) {
      ++unknown;
      continue;
    }
    obs.nodes.push_back(*idx);
    obs.likelihood.push_back(msg.likelihood[i]);
  }
  if (msg.nodes.size() != msg.likelihood.size())
    obs.likelihood.push_back(std::numeric_limits<double>::quiet_NaN());
  if (unknown_nodes) *unknown_nodes = unknown;
  if (msg.has_velocity) obs.velocity = Eigen::Vector2d(msg.velocity.x, msg.velocity.y);
  if (std::isfinite(msg.position.x) && std::isfinite(msg.position.y)) {
    obs.position = Eigen::Vector2d(msg.position.x, msg.position.y);
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c)
        obs.position_covariance(r, c) = msg.position_covariance[static_cast<std::size_t>(r * 3 + c)];
  }
  if (msg.has_bias) {
    obs.bias_removed = Eigen::Vector2d(msg.bias_removed.x, msg.bias_removed.y);
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 2; ++c)
        obs.bias_covariance(r, c) = msg.bias_covariance[static_cast<std::size_t>(r * 2 + c)];
    obs.bias_drift_rate = msg.bias_drift_rate;
  }
  return obs;
}

picker_localisation::PickerInfo toMsg(const core::PickerConfig& picker) {
  picker_localisation::PickerInfo m;
  m.id = picker.id;
  m.gnss_topic = picker.gnss_topic;
  m.rfid_tags = picker.rfid_tags;
  m.uwb_tag = picker.uwb_tag;
  return m;
}

core::PickerConfig fromMsg(const picker_localisation::PickerInfo& msg) {
  core::PickerConfig p;
  p.id = msg.id;
  p.gnss_topic = msg.gnss_topic;
  p.rfid_tags = msg.rfid_tags;
  p.uwb_tag = msg.uwb_tag;
  return p;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
