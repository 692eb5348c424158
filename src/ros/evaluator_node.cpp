#include "picker_localisation/ros/evaluator_node.h"

#include "picker_localisation/core/yaml_keys.h"
#include "picker_localisation/ros/param_yaml.h"

#include <cmath>
#include <limits>
#include <iostream>

#include "picker_localisation/TrackingError.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/eval/report.h"
#include "picker_localisation/ros/map_source.h"

namespace picker_localisation {
namespace ros_adapter {

const std::vector<std::string>& EvaluatorOptions::yamlKeys() {
  static const std::vector<std::string> keys{
      "pickers_file",       "sample_rate",      "duration", "output_csv", "ordering_latency",
      "max_truth_distance", "max_future_stamp", "map_file", "map_topic",  "belief_topic"};
  return keys;
}

EvaluatorOptions EvaluatorOptions::fromYaml(const YAML::Node& y, std::vector<std::string>* unknown) {
  EvaluatorOptions o;
  if (!y || !y.IsMap()) return o;
  const std::string c = "evaluator";
  core::readOption(y, c, "pickers_file", o.pickers_file);
  core::readOption(y, c, "sample_rate", o.sample_rate);
  core::readOption(y, c, "duration", o.duration);
  core::readOption(y, c, "output_csv", o.output_csv);
  core::readOption(y, c, "ordering_latency", o.ordering_latency);
  core::readOption(y, c, "max_truth_distance", o.max_truth_distance);
  core::readOption(y, c, "max_future_stamp", o.max_future_stamp);
  core::readOption(y, c, "belief_topic", o.belief_topic);
  core::readOption(y, c, "map_file", o.map_file);
  core::readOption(y, c, "map_topic", o.map_topic);
  return core::checkOptions(o, y, yamlKeys(), c, unknown);
}

std::string EvaluatorOptions::validate() const {
  const auto bad = core::badValue;
  if (!(sample_rate > 0.0) || !std::isfinite(sample_rate)) return bad("sample_rate", sample_rate, "finite and > 0");
  if (!(duration >= 0.0)) return bad("duration", duration, ">= 0 (0: none)");
  if (!(ordering_latency >= 0.0)) return bad("ordering_latency", ordering_latency, ">= 0");
  if (!(max_truth_distance > 0.0)) return bad("max_truth_distance", max_truth_distance, "> 0");
  if (!(max_future_stamp >= 0.0)) return bad("max_future_stamp", max_future_stamp, ">= 0");
  return "";
}

Evaluator::Evaluator(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  EvaluatorOptions o;
  if (!loadOptions(pnh, o)) return;
  std::string pickers_file = o.pickers_file;
  if (pickers_file.empty() && !nh.getParam("pickers_file", pickers_file)) {
    ROS_FATAL("evaluator: parameter ~pickers_file (config/pickers.yaml) is required");
    return;
  }
  const double sample_rate = o.sample_rate;
  duration_ = o.duration;
  output_csv_ = o.output_csv;
  ordering_latency_ = o.ordering_latency;
  max_truth_distance_ = o.max_truth_distance;
  clock_guard_ = StampGuard(o.max_future_stamp);
  core::PickerRegistry registry;
  try {
    registry = core::PickerRegistry::load(pickers_file);
  } catch (const std::exception& e) {
    ROS_FATAL("evaluator: %s", e.what());
    return;
  }
  core::CommonNodeOptions map_source;
  map_source.map_file = o.map_file;
  map_source.map_topic = o.map_topic;
  map_ = obtainMap(nh, map_source);
  if (!map_) return;
  pickers_.resize(registry.size());
  for (std::size_t i = 0; i < registry.size(); ++i) {
    Picker& p = pickers_[i];
    p.id = registry.pickers()[i].id;
    const std::string base = "/pickers/" + p.id;
    index_[p.id] = i;
    p.truth_sub = nh.subscribe<geometry_msgs::PoseStamped>(
        base + "/ground_truth", 10,
        [this, i](const geometry_msgs::PoseStamped::ConstPtr& m) { onTruth(i, m); });
    p.error_pub = nh.advertise<picker_localisation::TrackingError>(base + "/error", 10);
  }
  beliefs_ = std::make_unique<FleetBeliefs>(
      nh, o.belief_topic, [this](const picker_localisation::PickerBelief& b) { onBelief(b); });
  beliefs_->follow(registry.ids());
  diagnostics_.setHardwareID("evaluator");
  diagnostics_.add("evaluator", this, &Evaluator::diagnose);
  diagnostics_.input("ground truth", 5.0);
  diagnostics_.input("beliefs");
  diagnostics_.start(nh);
  // A map edited at run time: errors are measured on it from now on; the samples taken before name the node
  // each of theirs maps to on the new map (the same name, else the nearest), so the CSV uses one map.
  map_follower_ = std::make_unique<MapFollower>(
      nh, map_source, map_,
      [this](std::shared_ptr<const topology::TopologicalMap> m, const topology::MapChange& c) {
        for (Picker& p : pickers_)
          for (eval::ErrorSample& s : p.samples) {
            s.estimated_node = c.old_to_new.at(s.estimated_node);
            s.true_node = c.old_to_new.at(s.true_node);
          }
        map_ = std::move(m);
      });
  sample_period_ = 1.0 / sample_rate;
  // The timer only polls; samples fall on the stamp grid (see the header).
  timer_ = nh.createTimer(ros::Duration(std::min(sample_period_, 0.1)), &Evaluator::onTimer, this);
  ROS_INFO("evaluator: %zu pickers, map '%s', sampling at %g Hz%s", pickers_.size(), map_->name().c_str(),
           sample_rate,
           duration_ > 0.0
               ? (", stopping " + std::to_string(duration_) + " s after the first ground truth").c_str()
               : "");
  ok_ = true;
}

void Evaluator::onBelief(const picker_localisation::PickerBelief& belief) {
  diagnostics_.tick("beliefs");
  const auto found = index_.find(belief.picker_id);
  if (found == index_.end()) return;  // a picker this evaluation does not score
  Picker& p = pickers_[found->second];
  ++p.beliefs;
  if (belief.estimated_node.empty()) return;  // not initialised yet
  if (clock_guard_.tooFarInFuture(belief.header.stamp)) {
    ++p.future;
    ROS_WARN_THROTTLE(5.0, "evaluator: belief of %s stamped %.3f, far ahead of the clock (ignored)", p.id.c_str(),
                      belief.header.stamp.toSec());
    return;
  }
  if (!map_->index(belief.estimated_node)) {
    ++p.unknown_nodes;
    ROS_WARN_THROTTLE(5.0, "evaluator: belief of %s names unknown node '%s' (ignored)", p.id.c_str(),
                      belief.estimated_node.c_str());
    return;
  }
  p.belief_history.emplace_back(belief.header.stamp.toSec(), belief.estimated_node);
}

void Evaluator::onTruth(std::size_t i, const geometry_msgs::PoseStamped::ConstPtr& msg) {
  diagnostics_.tick("ground truth");
  Picker& p = pickers_[i];
  ++p.truths;
  const Eigen::Vector2d t(msg->pose.position.x, msg->pose.position.y);
  if (!t.allFinite()) {
    ++p.not_finite;
    ROS_WARN_THROTTLE(5.0, "evaluator: non-finite ground truth of %s (ignored)", p.id.c_str());
    return;
  }
  if (clock_guard_.tooFarInFuture(msg->header.stamp)) {
    ++p.future;
    ROS_WARN_THROTTLE(5.0, "evaluator: ground truth of %s stamped %.3f, far ahead of the clock (ignored)",
                      p.id.c_str(), msg->header.stamp.toSec());
    return;
  }
  // A truth far off the map would be scored against the nearest node as if the picker stood there.
  const double off = map_->distanceToNearestNode(t);
  if (max_truth_distance_ > 0.0 && off > max_truth_distance_) {
    ++p.off_map;
    ROS_WARN_THROTTLE(5.0, "evaluator: ground truth of %s is %.0f m from the nearest map node (> max_truth_distance "
                      "%.0f m; ignored)", p.id.c_str(), off, max_truth_distance_);
    return;
  }
  p.truth_history.emplace_back(msg->header.stamp.toSec(), t);
  if (first_truth_ < 0.0)
    first_truth_ = msg->header.stamp.isZero() ? ros::Time::now().toSec() : msg->header.stamp.toSec();
}

namespace {
// Latest entry stamped <= t (entries arrive roughly in stamp order; scans from the back), and drops entries
// that a later one already supersedes for every future t' >= t.
template <class T>
std::optional<T> latestAtOrBefore(std::deque<std::pair<double, T>>& history, double t) {
  std::optional<T> found;
  double best = -std::numeric_limits<double>::infinity();
  for (const auto& [stamp, value] : history)
    if (stamp <= t && stamp >= best) {  // >=: of equal stamps the later arrival wins
      best = stamp;
      found = value;
    }
  while (history.size() > 1 && history[1].first <= t) history.pop_front();
  return found;
}
}  // namespace

void Evaluator::sampleAt(double t) {
  for (Picker& p : pickers_) {
    if (auto n = latestAtOrBefore(p.belief_history, t)) p.estimated_node = *n;
    if (auto x = latestAtOrBefore(p.truth_history, t)) p.truth = *x;
    if (!p.estimated_node || !p.truth) continue;
    const auto estimated = map_->index(*p.estimated_node);
    if (!estimated)
      continue;  // a belief on a node the map lost in an edit: the tracker's next one will not be
    const eval::ErrorSample s = eval::computeError(*map_, *estimated, *p.truth, t, p.id);
    p.samples.push_back(s);
    picker_localisation::TrackingError msg;
    msg.header.stamp = ros::Time(t);
    msg.header.frame_id = "map";
    msg.picker_id = p.id;
    msg.estimated_node = *p.estimated_node;
    msg.true_node = map_->node(s.true_node).name;
    msg.euclidean_error = s.euclidean;
    msg.topological_error = s.topological;
    msg.in_true_lane = s.in_true_lane;
    p.error_pub.publish(msg);
  }
}

void Evaluator::onTimer(const ros::TimerEvent&) {
  if (clock_guard_.clockJumpedBack()) {
    // A looping bag or a restarted simulator: sample the new time line from its first ground truth (the errors
    // scored so far are kept).
    ROS_WARN("evaluator: the clock jumped back: sampling restarts with the next ground truth");
    first_truth_ = next_sample_ = -1.0;
    for (Picker& p : pickers_) {
      p.belief_history.clear();
      p.truth_history.clear();
      p.truth.reset();
      p.estimated_node.reset();
    }
  }
  if (done_ || first_truth_ < 0.0) return;
  const double now = ros::Time::now().toSec();
  if (next_sample_ < 0.0) next_sample_ = std::ceil(first_truth_ / sample_period_) * sample_period_;
  // A first truth stamped long before the clock (or a long pause) would be caught up one period at a time
  // (a billion samples for a stamp near 0 under wall time): only the last max_catch_up s are sampled.
  const double oldest = now - ordering_latency_ - max_catch_up_;
  if (next_sample_ < oldest) {
    ROS_WARN_THROTTLE(5.0, "evaluator: %.0f s of stamp time not sampled (ground truth stamped long before the clock)",
                      oldest - next_sample_);
    next_sample_ = std::ceil(oldest / sample_period_) * sample_period_;
  }
  while (!done_ && next_sample_ <= now - ordering_latency_) {
    sampleAt(next_sample_);
    if (duration_ > 0.0 && next_sample_ >= first_truth_ + duration_) done_ = true;
    next_sample_ += sample_period_;
  }
  if (done_) {
    finish();
    ros::shutdown();
  }
}

std::string Evaluator::table() const {
  std::vector<std::pair<std::string, std::vector<eval::ErrorSample>>> rows;
  for (const Picker& p : pickers_) rows.emplace_back(p.id, p.samples);
  return eval::errorTable(rows);
}

void Evaluator::finish() {
  if (finished_ || !ok_) return;
  finished_ = true;
  const std::string t = table();
  std::cout << "\n== evaluator: tracking errors (" << map_->name() << ") ==\n" << t << std::flush;
  if (!output_csv_.empty()) {
    std::vector<eval::ErrorSample> all;
    for (const Picker& p : pickers_) all.insert(all.end(), p.samples.begin(), p.samples.end());
    try {
      eval::writeRunCsv(output_csv_, *map_, all);
    } catch (const std::exception& e) {
      std::cerr << "evaluator: " << e.what() << "\n";
    }
  }
}

void Evaluator::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::size_t waiting = 0, rejected = 0, off_map = 0, future = 0;
  for (const Picker& p : pickers_) {
    stat.add(p.id + " beliefs", p.beliefs);
    stat.add(p.id + " ground truths", p.truths);
    stat.add(p.id + " samples", p.samples.size());
    if (!p.estimated_node || !p.truth) ++waiting;
    rejected += p.unknown_nodes + p.not_finite + p.off_map + p.future;
    off_map += p.off_map;
    future += p.future;
  }
  stat.add("rejected messages", rejected);
  stat.add("ground truths off the map", off_map);
  stat.add("stamped in the future", future);
  stat.add("clock jumps back", clock_guard_.jumps());
  if (rejected > 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "rejected beliefs / ground truths (see counts)");
  else if (waiting > 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 std::to_string(waiting) + " picker(s) without belief or truth");
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "evaluating");
}

}  // namespace ros_adapter
}  // namespace picker_localisation
