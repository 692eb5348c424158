#include "picker_localisation/ros/tpf_tracker.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>

#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/ros/observation_conversions.h"

namespace picker_localisation {
namespace ros_adapter {

namespace {

ros::Time rosTime(double stamp) {
  return ros::Time(std::max(0.0, std::isfinite(stamp) ? stamp : 0.0));
}

// Blue (low) -> red (high) for a mass relative to the largest.
std_msgs::ColorRGBA massColour(double relative) {
  std_msgs::ColorRGBA c;
  const double r = std::clamp(relative, 0.0, 1.0);
  c.r = static_cast<float>(r);
  c.g = static_cast<float>(0.2 * (1.0 - r));
  c.b = static_cast<float>(1.0 - r);
  c.a = static_cast<float>(0.35 + 0.65 * r);
  return c;
}

}  // namespace

tpf::TpfParams tpfParamsFromRos(const ros::NodeHandle& pnh) {
  YAML::Node merged(YAML::NodeType::Map);
  std::string file;
  if (pnh.getParam("tpf_params_file", file) && !file.empty()) {
    try {
      merged = YAML::LoadFile(file);
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(file + ": " + e.what());
    }
    if (!merged.IsMap()) merged = YAML::Node(YAML::NodeType::Map);
  }
  for (const auto& kv : paramsAsYaml(pnh)) merged[kv.first.as<std::string>()] = kv.second;
  return tpf::TpfParams::fromYaml(merged);
}

std::uint64_t seedFromId(const std::string& id) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : id) h = (h ^ c) * 1099511628211ull;
  return h == 0 ? 1 : h;
}

picker_localisation::PickerBelief toBeliefMsg(const tpf::Belief& b, const topology::TopologicalMap& map,
                                              const std::string& picker_id, const std::string& frame_id) {
  picker_localisation::PickerBelief m;
  m.header.stamp = rosTime(b.stamp);
  m.header.frame_id = frame_id;
  m.picker_id = picker_id;
  m.nodes.reserve(b.nodes.size());
  for (auto n : b.nodes) m.nodes.push_back(map.node(n).name);
  m.masses = b.masses;
  if (b.map_node != topology::kInvalidNode && b.map_node < map.numNodes()) {
    const auto& node = map.node(b.map_node);
    m.estimated_node = node.name;
    m.estimated_lane = map.laneNameOf(b.map_node);
    m.estimated_pose.position.x = node.position.x();
    m.estimated_pose.position.y = node.position.y();
    m.estimated_pose.position.z = node.position.z();
    m.estimated_pose.orientation.x = node.orientation[0];
    m.estimated_pose.orientation.y = node.orientation[1];
    m.estimated_pose.orientation.z = node.orientation[2];
    m.estimated_pose.orientation.w = node.orientation[3];
  } else {
    m.estimated_pose.orientation.w = 1.0;
  }
  m.entropy = b.entropy;
  m.jsd = b.jsd;
  m.reinitialised = b.reinitialised;
  m.unconnected_jump_probability = b.unconnected_jump_probability;
  m.particle_count = static_cast<std::uint32_t>(b.particle_count);
  m.observations = static_cast<std::uint32_t>(b.observations);
  return m;
}

geometry_msgs::PoseWithCovarianceStamped toEstimateMsg(const tpf::Belief& b,
                                                       const topology::TopologicalMap& map,
                                                       const std::string& frame_id) {
  geometry_msgs::PoseWithCovarianceStamped m;
  m.header.stamp = rosTime(b.stamp);
  m.header.frame_id = frame_id;
  m.pose.pose.orientation.w = 1.0;
  if (b.map_node == topology::kInvalidNode || b.map_node >= map.numNodes()) return m;
  const auto& node = map.node(b.map_node);
  m.pose.pose.position.x = node.position.x();
  m.pose.pose.position.y = node.position.y();
  m.pose.pose.position.z = node.position.z();
  m.pose.pose.orientation.x = node.orientation[0];
  m.pose.pose.orientation.y = node.orientation[1];
  m.pose.pose.orientation.z = node.orientation[2];
  m.pose.pose.orientation.w = node.orientation[3];
  // Spread of the belief about the MAP node's position (m^2), mass-weighted; z and rotations unknown.
  const Eigen::Vector2d c = map.position2d(b.map_node);
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (std::size_t k = 0; k < b.nodes.size(); ++k) {
    const Eigen::Vector2d d = map.position2d(b.nodes[k]) - c;
    cov += b.masses[k] * d * d.transpose();
  }
  m.pose.covariance[0] = cov(0, 0);
  m.pose.covariance[1] = cov(0, 1);
  m.pose.covariance[6] = cov(1, 0);
  m.pose.covariance[7] = cov(1, 1);
  m.pose.covariance[14] = 1e6;
  m.pose.covariance[21] = 1e6;
  m.pose.covariance[28] = 1e6;
  m.pose.covariance[35] = 1e6;
  return m;
}

visualization_msgs::MarkerArray toMarkers(const tpf::Belief& b, const topology::TopologicalMap& map,
                                          const std::string& picker_id, const std::string& frame_id) {
  visualization_msgs::MarkerArray arr;
  visualization_msgs::Marker nodes;
  nodes.header.stamp = rosTime(b.stamp);
  nodes.header.frame_id = frame_id;
  nodes.ns = picker_id + "/belief";
  nodes.id = 0;
  nodes.type = visualization_msgs::Marker::SPHERE_LIST;
  nodes.action = visualization_msgs::Marker::ADD;
  nodes.pose.orientation.w = 1.0;
  nodes.scale.x = nodes.scale.y = nodes.scale.z = 0.6;
  double max_mass = 0.0;
  for (double m : b.masses) max_mass = std::max(max_mass, m);
  for (std::size_t k = 0; k < b.nodes.size(); ++k) {
    geometry_msgs::Point p;
    const auto& pos = map.node(b.nodes[k]).position;
    p.x = pos.x();
    p.y = pos.y();
    p.z = pos.z() + 0.1;
    nodes.points.push_back(p);
    nodes.colors.push_back(massColour(max_mass > 0.0 ? b.masses[k] / max_mass : 0.0));
  }
  if (nodes.points.empty()) nodes.action = visualization_msgs::Marker::DELETE;
  arr.markers.push_back(nodes);

  visualization_msgs::Marker label;
  label.header = nodes.header;
  label.ns = picker_id + "/estimate";
  label.id = 1;
  label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
  label.pose.orientation.w = 1.0;
  label.scale.z = 0.8;
  label.color.r = label.color.g = label.color.b = label.color.a = 1.0f;
  if (b.map_node != topology::kInvalidNode && b.map_node < map.numNodes()) {
    const auto& pos = map.node(b.map_node).position;
    label.action = visualization_msgs::Marker::ADD;
    label.pose.position.x = pos.x();
    label.pose.position.y = pos.y();
    label.pose.position.z = pos.z() + 1.2;
    label.text = picker_id;
  } else {
    label.action = visualization_msgs::Marker::DELETE;
  }
  arr.markers.push_back(label);
  return arr;
}

TpfTracker::TpfTracker(ros::NodeHandle& nh, ros::NodeHandle& pnh) : diagnostics_(nh, pnh) {
  if (!pnh.getParam("picker_id", picker_id_) || picker_id_.empty()) {
    ROS_FATAL("tpf_tracker: parameter ~picker_id is required");
    return;
  }
  pnh.param<std::string>("frame_id", frame_id_, "map");
  tpf::TpfParams params;
  try {
    params = tpfParamsFromRos(pnh);
  } catch (const std::exception& e) {
    ROS_FATAL("tpf_tracker %s: %s", picker_id_.c_str(), e.what());
    return;
  }
  int seed_param = 0;
  pnh.param("seed", seed_param, 0);
  const std::uint64_t seed = seed_param > 0 ? static_cast<std::uint64_t>(seed_param) : seedFromId(picker_id_);
  map_ = obtainMap(nh, pnh);
  if (!map_) return;  // obtainMap logged why
  filter_ = std::make_unique<tpf::TopologicalParticleFilter>(map_, params, seed);

  std::string prefix, observations_topic;
  pnh.param<std::string>("topic_prefix", prefix, "/pickers");
  pnh.param<std::string>("observations_topic", observations_topic, "/observations");
  const std::string base = prefix + "/" + picker_id_;
  belief_pub_ = nh.advertise<picker_localisation::PickerBelief>(base + "/belief", 10, true);
  estimate_pub_ = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>(base + "/estimate", 10, true);
  markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>(base + "/markers", 2, true);
  reset_srv_ = nh.advertiseService(base + "/reset", &TpfTracker::reset, this);
  what_if_srv_ = nh.advertiseService(base + "/what_if", &TpfTracker::whatIf, this);
  sub_ = nh.subscribe(observations_topic, 200, &TpfTracker::observationCallback, this);
  pnh.param("ordering_latency", ordering_latency_, ordering_latency_);
  stamp_guard_ = StampGuard(pnh.param("max_future_stamp", 10.0));
  ordering_ = core::StampOrderedBuffer<std::pair<core::Observation, std::string>>(std::max(0.0, ordering_latency_));
  if (ordering_latency_ > 0.0)
    ordering_timer_ = nh.createTimer(ros::Duration(std::min(0.05, ordering_latency_ / 4.0)),
                                     &TpfTracker::orderingCallback, this);
  if (params.prediction_rate > 0.0) {
    prediction_period_ = 1.0 / params.prediction_rate;
    // Ticks at 4x the rate so a prediction happens within a quarter period of falling due.
    timer_ = nh.createTimer(ros::Duration(prediction_period_ / 4.0), &TpfTracker::timerCallback, this);
  }
  diagnostics_.setHardwareID(picker_id_);
  diagnostics_.add("tpf_tracker " + picker_id_, this, &TpfTracker::diagnose);
  diagnostics_timer_ =
      nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { diagnostics_.update(); });
  ROS_INFO("tpf_tracker %s: %zu particles, method %s motion, map '%s' (%zu nodes), prediction every %.1f s",
           picker_id_.c_str(), params.num_particles, tpf::toString(params.motion_model), map_->name().c_str(),
           map_->numNodes(), prediction_period_);
}

void TpfTracker::observationCallback(const picker_localisation::Observation::ConstPtr& msg) {
  ++received_;
  if (!core::concernsPicker(msg->identifying, msg->picker_id, msg->candidate_pickers, picker_id_)) {
    ++other_picker_;  // another picker's (identifying, or an anonymous one this picker cannot be)
    return;
  }
  checkClockJump();
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) {
    // Adopting it would make every later observation "too old" and start ~(stamp - now) / period predictions.
    ROS_WARN_THROTTLE(5.0, "tpf_tracker %s: %s observation stamped %.3f is more than %.1f s ahead of the clock: dropped",
                      picker_id_.c_str(), msg->sensor.c_str(), msg->header.stamp.toSec(), stamp_guard_.maxFuture());
    return;
  }
  std::size_t unknown = 0;
  core::Observation obs = fromMsg(*msg, *map_, &unknown);
  if (unknown > 0) {
    unknown_nodes_ += unknown;
    ROS_WARN_THROTTLE(5.0, "tpf_tracker %s: %zu node name(s) of a %s observation are not in the map (skipped)",
                      picker_id_.c_str(), unknown, msg->sensor.c_str());
  }
  if (ordering_latency_ <= 0.0) {
    process(obs, msg->sensor);
    return;
  }
  // Tie-break equal stamps by content so the fusion order never depends on arrival order.
  std::string key = msg->sensor + "|" + msg->robot_id + "|" + msg->picker_id + "|";
  for (std::size_t i = 0; i < msg->nodes.size() && i < msg->likelihood.size(); ++i)
    key += msg->nodes[i] + ":" + std::to_string(msg->likelihood[i]) + ",";
  ordering_.push(obs.stamp, key, {std::move(obs), msg->sensor});
}

void TpfTracker::checkClockJump() {
  if (!stamp_guard_.clockJumpedBack()) return;
  ROS_WARN("tpf_tracker %s: the clock jumped back: belief reset, %zu waiting observation(s) dropped", picker_id_.c_str(),
           ordering_.size());
  ordering_.clear();
  filter_->reset();
  ++resets_;
  publish();
}

void TpfTracker::orderingCallback(const ros::TimerEvent&) {
  checkClockJump();
  const double now = ros::Time::now().toSec();
  if (now <= 0.0) return;
  for (auto& item : ordering_.release(now)) process(item.second.first, item.second.second);
}

void TpfTracker::predictDueUntil(double until) {
  if (prediction_period_ <= 0.0) return;
  int steps = 0;
  while (filter_->initialised() && until - filter_->lastStamp() >= prediction_period_) {
    const double next = ++steps < kMaxPredictionsPerCall ? filter_->lastStamp() + prediction_period_
                                                          : until;  // a long silence: one step to `until`
    if (!filter_->predictTo(next)) break;
    publish();
  }
}

void TpfTracker::process(const core::Observation& obs, const std::string& sensor) {
  if (std::isfinite(obs.stamp)) predictDueUntil(obs.stamp);
  const tpf::UpdateResult r = filter_->update(obs);
  if (!r.ok()) {
    if (r.status != tpf::UpdateStatus::kIgnoredSensor) {
      last_problem_ = std::string(tpf::toString(r.status)) + ": " + r.reason;
      ROS_WARN_THROTTLE(5.0, "tpf_tracker %s: %s observation %s", picker_id_.c_str(), sensor.c_str(),
                        last_problem_.c_str());
    }
    return;
  }
  if (r.reinitialised)
    ROS_INFO_THROTTLE(5.0, "tpf_tracker %s: re-initialised (JSD %.3f)", picker_id_.c_str(), filter_->belief().jsd);
  publish();
}

void TpfTracker::timerCallback(const ros::TimerEvent&) {
  checkClockJump();
  const double now = ros::Time::now().toSec();
  if (now <= 0.0 || !filter_->initialised()) return;  // sim clock not running yet / nothing to predict
  // Predictions wait for the ordering latency too, so none overtakes an observation still in the buffer.
  predictDueUntil(now - std::max(0.0, ordering_latency_));
}

bool TpfTracker::reset(picker_localisation::ResetBelief::Request&,
                       picker_localisation::ResetBelief::Response& res) {
  filter_->reset();
  ++resets_;
  res.success = true;
  res.message = "belief of " + picker_id_ + " forgotten; the next observation initialises it";
  publish();
  return true;
}

bool TpfTracker::whatIf(picker_localisation::WhatIf::Request& req,
                        picker_localisation::WhatIf::Response& res) {
  ++what_if_calls_;
  if (!std::isfinite(req.horizon) || req.horizon < 0.0) {
    res.success = false;
    res.message = "horizon must be finite and >= 0";
    return true;
  }
  tpf::Belief b;
  if (req.with_observation) {
    const core::Observation obs = fromMsg(req.observation, *map_);
    tpf::UpdateResult r;
    b = filter_->posteriorUnder(obs, req.horizon, req.seed, &r);
    if (!r.ok()) {
      res.success = false;
      res.message = std::string("hypothetical observation ") + tpf::toString(r.status) + ": " + r.reason;
      res.belief = toBeliefMsg(b, *map_, picker_id_, frame_id_);
      return true;
    }
  } else {
    if (!filter_->initialised()) {
      res.success = false;
      res.message = "no belief yet: " + picker_id_ + " has received no observation";
      res.belief = toBeliefMsg(filter_->belief(), *map_, picker_id_, frame_id_);
      return true;
    }
    b = filter_->predictAhead(req.horizon, req.seed);
  }
  res.success = true;
  res.belief = toBeliefMsg(b, *map_, picker_id_, frame_id_);
  return true;
}

void TpfTracker::publish() {
  const tpf::Belief& b = filter_->belief();
  belief_pub_.publish(toBeliefMsg(b, *map_, picker_id_, frame_id_));
  if (b.initialised) estimate_pub_.publish(toEstimateMsg(b, *map_, frame_id_));
  markers_pub_.publish(toMarkers(b, *map_, picker_id_, frame_id_));
}

void TpfTracker::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const auto& c = filter_->counters();
  const std::uint64_t problems = c.rejected_invalid + c.dropped_too_old;
  stat.add("picker_id", picker_id_);
  // Input rate over the last diagnostics period (wall time: the rate at which this node is fed).
  const ros::WallTime now = ros::WallTime::now();
  if (!last_diag_time_.isZero() && now > last_diag_time_)
    stat.add("observation rate (Hz)",
             static_cast<double>(received_ - last_diag_received_) / (now - last_diag_time_).toSec());
  last_diag_time_ = now;
  last_diag_received_ = received_;
  stat.add("observations received", received_);
  stat.add("observations stamped in the future (dropped)", stamp_guard_.futureStamps());
  stat.add("clock jumps back (belief reset)", stamp_guard_.jumps());
  stat.add("observations waiting for stamp order", ordering_.size());
  stat.add("ordering overflows", ordering_.forcedReleases());
  stat.add("accepted", c.accepted);
  stat.add("reordered (late, within window)", c.reordered);
  stat.add("dropped (too old)", c.dropped_too_old);
  stat.add("rejected (invalid)", c.rejected_invalid);
  stat.add("ignored (sensor not fused in this mode)", c.ignored_sensor);
  stat.add("ignored (another picker's)", other_picker_);
  stat.add("unknown node names skipped", unknown_nodes_);
  stat.add("re-initialisations", c.reinitialisations);
  stat.add("no-overlap updates", c.no_overlap);
  stat.add("predictions", c.predictions);
  stat.add("what-if calls", what_if_calls_);
  stat.add("resets", resets_);
  const auto& b = filter_->belief();
  stat.add("entropy (nats)", b.entropy);
  stat.add("jsd", b.jsd);
  stat.add("p_rj", b.unconnected_jump_probability);
  if (b.initialised && b.map_node < map_->numNodes()) stat.add("estimated node", map_->node(b.map_node).name);
  if (problems > last_reported_problems_) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, last_problem_);
  } else if (!b.initialised) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "waiting for the first observation");
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  }
  last_reported_problems_ = problems;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
