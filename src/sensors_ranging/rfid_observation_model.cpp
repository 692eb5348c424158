#include "picker_localisation/sensors_ranging/rfid_observation_model.h"

#include "picker_localisation/core/yaml_file.h"
#include "picker_localisation/core/yaml_keys.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace picker_localisation {
namespace sensors {

RfidModelOptions RfidModelOptions::fromYaml(const YAML::Node& y, std::vector<std::string>* unknown) {
  RfidModelOptions o;
  if (!y || !y.IsMap()) return o;
  const std::string c = "rfid_ranging";
  core::readOption(y, c, "read_model", o.read_model);
  core::readOption(y, c, "p_max", o.p_max);
  core::readOption(y, c, "d50", o.d50);
  core::readOption(y, c, "width", o.width);
  core::readOption(y, c, "max_range", o.max_range);
  core::readOption(y, c, "height_difference", o.height_difference);
  core::readOption(y, c, "min_relative", o.min_relative);
  core::readOption(y, c, "read_range", o.read_range);
  core::readOption(y, c, "beam_half_angle", o.beam_half_angle);
  core::readOption(y, c, "min_rssi", o.min_rssi);
  core::readOption(y, c, "out_of_order_tolerance", o.out_of_order_tolerance);
  core::readOption(y, c, "negative_information", o.negative_information);
  core::readOption(y, c, "negative_window", o.negative_window);
  core::readOption(y, c, "negative_period", o.negative_period);
  core::readOption(y, c, "p_detect", o.p_detect);
  core::readOption(y, c, "attempt_rate", o.attempt_rate);
  core::readOption(y, c, "max_failed_attempts", o.max_failed_attempts);
  return core::checkOptions(o, y, yamlKeys(), c, unknown);
}

std::string RfidModelOptions::validate() const {
  const auto bad = core::badValue;
  if (read_model != "logistic" && read_model != "disc")
    return "read_model = " + read_model + ": must be logistic or disc";
  if (!(attempt_rate >= 0.0) || !std::isfinite(attempt_rate))
    return bad("attempt_rate", attempt_rate, "finite and >= 0");
  if (max_failed_attempts < 0) return bad("max_failed_attempts", max_failed_attempts, ">= 0");
  if (!(p_detect >= 0.0 && p_detect <= 1.0)) return bad("p_detect", p_detect, "in [0, 1]");
  if (read_model == "disc") {
    if (!(read_range > 0.0) || !std::isfinite(read_range))
      return bad("read_range", read_range, "finite and > 0");
    return "";
  }
  if (!(p_max > 0.0 && p_max <= 1.0)) return bad("p_max", p_max, "in (0, 1]");
  if (!(width > 0.0) || !std::isfinite(width)) return bad("width", width, "finite and > 0");
  if (!(max_range > 0.0) || !std::isfinite(max_range)) return bad("max_range", max_range, "finite and > 0");
  if (!(min_relative > 0.0 && min_relative < 1.0)) return bad("min_relative", min_relative, "in (0, 1)");
  if (!(d50 > 0.0) || !std::isfinite(d50)) return bad("d50", d50, "finite and > 0");
  if (!std::isfinite(height_difference)) return bad("height_difference", height_difference, "finite");
  return "";
}

const std::vector<std::string>& RfidModelOptions::yamlKeys() {
  static const std::vector<std::string> keys{"read_model",
                                             "p_max",
                                             "d50",
                                             "width",
                                             "max_range",
                                             "height_difference",
                                             "min_relative",
                                             "read_range",
                                             "beam_half_angle",
                                             "min_rssi",
                                             "out_of_order_tolerance",
                                             "negative_information",
                                             "negative_window",
                                             "negative_period",
                                             "attempt_rate",
                                             "max_failed_attempts",
                                             "p_detect"};
  return keys;
}

RfidModelOptions RfidModelOptions::fromYamlFile(const std::string& path, std::vector<std::string>* unknown) {
  return core::parseYamlFile(path, [&](const YAML::Node& root) { return fromYaml(root, unknown); });
}

const char* toString(RfidRejection r) {
  switch (r) {
    case RfidRejection::kNone:
      return "accepted";
    case RfidRejection::kUnknownTag:
      return "unknown_tag";
    case RfidRejection::kNotFinite:
      return "not_finite";
    case RfidRejection::kWeakSignal:
      return "weak_signal";
    case RfidRejection::kOutOfOrder:
      return "out_of_order";
  }
  return "unknown";
}

RfidObservationModel::RfidObservationModel(core::PickerRegistry registry,
                                           std::shared_ptr<const topology::TopologicalMap> map,
                                           RfidModelOptions options)
    : registry_(std::move(registry)), map_(std::move(map)), options_(options) {
  if (!map_) throw std::invalid_argument("RfidObservationModel: no map");
  const std::string problem = options_.validate();
  if (!problem.empty()) throw std::invalid_argument("RfidObservationModel: " + problem);
  if (options_.read_model == "disc") {
    logistic_ = false;
    region_radius_ = options_.read_range;
    position_variance_ = options_.read_range * options_.read_range / 4.0;  // uniform disc: R^2 / 4 per axis
    return;
  }
  // Cut-off: p_read(d) / p_max >= min_relative  <=>  d <= d50 + width ln(1 / min_relative - 1) (3D distance).
  const double cutoff_3d = std::min(
      options_.max_range, options_.d50 + options_.width * std::log(1.0 / options_.min_relative - 1.0));
  const double h2 = options_.height_difference * options_.height_difference;
  region_radius_ = cutoff_3d * cutoff_3d > h2 ? std::sqrt(cutoff_3d * cutoff_3d - h2) : 0.0;
  // Position covariance of the read: p_read-weighted second moment over the disc of radius r_c, per axis
  // 0.5 * int p(r) r^3 dr / int p(r) r dr (midpoint rule; the curve is smooth on [0, r_c]).
  double m1 = 0.0, m3 = 0.0;
  const int steps = 1000;
  const double dr = region_radius_ / steps;
  for (int i = 0; i < steps; ++i) {
    const double r = (i + 0.5) * dr, w = readProbability(r);
    m1 += w * r;
    m3 += w * r * r * r;
  }
  position_variance_ = m1 > 0.0 ? 0.5 * m3 / m1 : 0.01;
}

double RfidObservationModel::readProbability(double planar_distance) const {
  if (!logistic_) return planar_distance <= options_.read_range ? 1.0 : 0.0;
  const double d = std::hypot(planar_distance, options_.height_difference);
  if (!(d >= 0.0) || d > options_.max_range) return 0.0;
  return options_.p_max / (1.0 + std::exp((d - options_.d50) / options_.width));
}

std::vector<topology::NodeIndex> RfidObservationModel::nodesInReadRegion(const Eigen::Vector3d& pose) const {
  std::vector<topology::NodeIndex> nodes = map_->nodesWithin(pose.head<2>(), region_radius_);
  if (options_.beam_half_angle < M_PI) {
    nodes.erase(std::remove_if(nodes.begin(), nodes.end(),
                               [&](topology::NodeIndex n) {
                                 const Eigen::Vector2d d = map_->position2d(n) - pose.head<2>();
                                 if (d.norm() < 1e-9) return false;  // the antenna's own node
                                 const double a =
                                     std::remainder(std::atan2(d.y(), d.x()) - pose.z(), 2.0 * M_PI);
                                 return std::abs(a) > options_.beam_half_angle;
                               }),
                nodes.end());
  }
  std::sort(nodes.begin(), nodes.end());
  return nodes;
}

void RfidObservationModel::reset() {
  antenna_last_stamp_.clear();
  antenna_session_start_.clear();
  last_read_.clear();
  last_negative_.clear();
}

RfidResult RfidObservationModel::process(const RfidRead& read) {
  RfidResult result;
  ++counters_.received;
  auto reject = [&](RfidRejection r, const std::string& why, std::size_t& counter) {
    result.rejection = r;
    result.reason = why;
    ++counter;
    return result;
  };
  // A NaN / Inf RSSI is a corrupted read, not a reader without RSSI (those report a number): rejected.
  if (!std::isfinite(read.stamp) || !read.antenna_pose.allFinite() || !std::isfinite(read.rssi))
    return reject(RfidRejection::kNotFinite, "stamp, antenna pose or RSSI is NaN/Inf", counters_.not_finite);
  const std::optional<std::string> picker = registry_.pickerForRfidTag(read.tag_id);
  if (!picker)
    return reject(RfidRejection::kUnknownTag, "unknown tag '" + read.tag_id + "'", counters_.unknown_tag);
  if (read.rssi < options_.min_rssi) {
    std::ostringstream s;
    s << "RSSI " << read.rssi << " dBm below min_rssi " << options_.min_rssi;
    return reject(RfidRejection::kWeakSignal, s.str(), counters_.weak_signal);
  }
  auto last = antenna_last_stamp_.find(read.frame_id);
  if (last != antenna_last_stamp_.end() && read.stamp < last->second - options_.out_of_order_tolerance) {
    std::ostringstream s;
    s << "stamp " << read.stamp << " s is older than the antenna's newest read (" << last->second << " s)";
    return reject(RfidRejection::kOutOfOrder, s.str(), counters_.out_of_order);
  }
  // Reading spell of this antenna (for negative information).
  if (last == antenna_last_stamp_.end() || read.stamp - last->second > options_.negative_window)
    antenna_session_start_[read.frame_id] = read.stamp;
  antenna_last_stamp_[read.frame_id] =
      std::max(read.stamp, last == antenna_last_stamp_.end() ? read.stamp : last->second);
  // Failed attempts of this antenna on this picker's tag since its previous read (see attempt_rate). The
  // first read of the tag, or one after a gap longer than the cap covers, follows max_failed_attempts: the
  // reader inventories all the time, so a tag read only now was not read while the robot came into range
  // (counting none there placed it next to the antenna, and a gap of 5.1 s counted 0 where 5.0 s counted 9).
  int failed = 0;
  if (options_.attempt_rate > 0.0 && logistic_) {
    auto prev = last_read_.find({read.frame_id, *picker});
    const double gap =
        prev == last_read_.end() ? std::numeric_limits<double>::infinity() : read.stamp - prev->second;
    if (gap > 0.0) {  // attempts in the gap, bounded before rounding (an infinite gap has no lround)
      const double attempts = std::min(gap * options_.attempt_rate, options_.max_failed_attempts + 1.0);
      failed = std::clamp(static_cast<int>(std::lround(attempts)) - 1, 0, options_.max_failed_attempts);
    }
  }
  last_read_[{read.frame_id, *picker}] = read.stamp;
  ++counters_.accepted;

  core::Observation obs;
  obs.stamp = read.stamp;
  obs.sensor = options_.sensor;
  obs.robot_id = read.robot_id;
  obs.picker_id = *picker;
  obs.identifying = true;
  obs.nodes = nodesInReadRegion(read.antenna_pose);
  if (obs.nodes.empty()) {
    obs.nodes.push_back(map_->nearestNode(read.antenna_pose.head<2>()));
    obs.likelihood.assign(1, 1.0);
  } else {
    obs.likelihood.reserve(obs.nodes.size());
    for (topology::NodeIndex n : obs.nodes) {  // L(n) = p_read(d(n)) (1 - p_read(d(n)))^m; the TPF normalises
      const double p = readProbability((map_->position2d(n) - read.antenna_pose.head<2>()).norm());
      obs.likelihood.push_back(p * std::pow(std::max(1.0 - p, 1e-3), failed));
    }
  }
  obs.position = read.antenna_pose.head<2>();
  obs.position_covariance = Eigen::Matrix2d::Identity() * position_variance_;
  result.observation = std::move(obs);
  if (options_.negative_information) result.negative = negativeObservations(read, *picker);
  return result;
}

std::vector<core::Observation> RfidObservationModel::negativeObservations(const RfidRead& read,
                                                                          const std::string& read_picker) {
  std::vector<core::Observation> out;
  // The antenna must have been reading for a whole window before absence of a read means anything.
  if (read.stamp - antenna_session_start_[read.frame_id] < options_.negative_window) return out;
  std::vector<topology::NodeIndex> inside;
  bool inside_computed = false;
  for (const core::PickerConfig& p : registry_.pickers()) {
    if (p.id == read_picker || p.rfid_tags.empty()) continue;
    const std::pair<std::string, std::string> key{read.frame_id, p.id};
    auto lr = last_read_.find(key);
    if (lr != last_read_.end() && read.stamp - lr->second <= options_.negative_window) continue;
    auto ln = last_negative_.find(key);
    if (ln != last_negative_.end() && read.stamp - ln->second < options_.negative_period) continue;
    if (!inside_computed) {
      inside = nodesInReadRegion(read.antenna_pose);
      inside_computed = true;
    }
    if (inside.empty()) continue;  // nothing to lower
    core::Observation obs;
    obs.stamp = read.stamp;
    obs.sensor = options_.sensor;
    obs.robot_id = read.robot_id;
    obs.picker_id = p.id;
    obs.identifying = true;
    core::setLikelihoodOverEveryNode(obs, map_->numNodes());
    // L(n) = 1 - p_detect * p_read(d(n)) / p_max (disc: 1 - p_detect inside), floored away from 0.
    const double scale = logistic_ ? options_.p_detect / options_.p_max : options_.p_detect;
    for (topology::NodeIndex n : inside) {
      const double p = readProbability((map_->position2d(n) - read.antenna_pose.head<2>()).norm());
      obs.likelihood[n] = std::max(1.0 - scale * p, 1e-6);
    }
    last_negative_[key] = read.stamp;
    ++counters_.negative_sent;
    out.push_back(std::move(obs));
  }
  return out;
}

}  // namespace sensors
}  // namespace picker_localisation
