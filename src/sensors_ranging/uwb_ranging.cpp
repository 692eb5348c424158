#include "picker_localisation/sensors_ranging/uwb_ranging.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "picker_localisation/core/yaml_file.h"
#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace sensors {

std::optional<Eigen::Vector2d> relativePositionFromPathDifference(double r, double p, double d, bool positive_y) {
  if (!std::isfinite(r) || !std::isfinite(p) || !std::isfinite(d) || d <= 0.0 || r < 0.0 || std::abs(p) > d)
    return std::nullopt;
  const double x = (d * d + 2.0 * r * p - p * p) / (2.0 * d);
  const double y2 = r * r - x * x;
  const double y = y2 > 0.0 ? std::sqrt(y2) : 0.0;
  return Eigen::Vector2d(x, positive_y ? y : -y);
}

double pathDifferenceFromPhase(double phase_difference, double wavelength) {
  return phase_difference * wavelength / (2.0 * M_PI);
}

Eigen::Vector2d relativePositionFromAngle(double r, double angle) {
  return {r * std::cos(angle), r * std::sin(angle)};
}

Eigen::Matrix2d relativePositionCovariance(double r, double angle, double range_variance, double angle_sigma) {
  Eigen::Matrix2d rot;
  rot << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  const Eigen::Vector2d d(std::max(range_variance, 0.0), r * r * angle_sigma * angle_sigma);
  return rot * d.asDiagonal() * rot.transpose();
}

const char* toString(UwbRejection r) {
  switch (r) {
    case UwbRejection::kNone: return "accepted";
    case UwbRejection::kUnknownTag: return "unknown_tag";
    case UwbRejection::kNotFinite: return "not_finite";
    case UwbRejection::kNegativeRange: return "negative_range";
    case UwbRejection::kOutOfRange: return "out_of_range";
    case UwbRejection::kOutOfOrder: return "out_of_order";
  }
  return "unknown";
}

// The RHF's keys (names of Sarmento et al. 2024), then the ranging keys; the node's own:
// UwbRangingNodeOptions.
const std::vector<std::string>& UwbRangingOptions::yamlKeys() {
  static const std::vector<std::string> keys{
      "grid_size_x",     "grid_size_y",      "grid_resolution",  "max_speed",  "p_threshold",
      "p_min_uwb",       "p_min_cam",        "p_min_obs",        "p_min_inov", "default_range_sigma",
      "bearing_sigma",   "output_threshold", "camera_gate",      "max_range",  "batch_window",
      "bearing_max_age", "pdoa_mode",        "pdoa_angle_sigma", "min_sigma",  "cutoff_sigmas",
      "reset_after",     "max_output_sigma"};
  return keys;
}

UwbRangingOptions UwbRangingOptions::fromYaml(const YAML::Node& y, std::vector<std::string>* unknown) {
  UwbRangingOptions o;
  if (!y || !y.IsMap()) return o;
  const std::string c = "uwb_ranging";
  RhfOptions& h = o.rhf;
  core::readOption(y, c, "grid_size_x", h.size_x);
  core::readOption(y, c, "grid_size_y", h.size_y);
  core::readOption(y, c, "grid_resolution", h.resolution);
  core::readOption(y, c, "max_speed", h.max_speed);
  core::readOption(y, c, "p_threshold", h.p_threshold);
  core::readOption(y, c, "p_min_uwb", h.p_min_uwb);
  core::readOption(y, c, "p_min_cam", h.p_min_cam);
  core::readOption(y, c, "p_min_obs", h.p_min_obs);
  core::readOption(y, c, "p_min_inov", h.p_min_inov);
  core::readOption(y, c, "default_range_sigma", h.default_range_sigma);
  core::readOption(y, c, "bearing_sigma", h.default_bearing_sigma);
  core::readOption(y, c, "output_threshold", h.output_threshold);
  core::readOption(y, c, "camera_gate", h.camera_gate);
  core::readOption(y, c, "max_range", o.max_range);
  core::readOption(y, c, "batch_window", o.batch_window);
  core::readOption(y, c, "bearing_max_age", o.bearing_max_age);
  core::readOption(y, c, "pdoa_mode", o.pdoa_mode);
  core::readOption(y, c, "pdoa_angle_sigma", o.pdoa_angle_sigma);
  core::readOption(y, c, "min_sigma", o.min_sigma);
  core::readOption(y, c, "cutoff_sigmas", o.cutoff_sigmas);
  core::readOption(y, c, "reset_after", o.reset_after);
  core::readOption(y, c, "max_output_sigma", o.max_output_sigma);
  return core::checkOptions(o, y, yamlKeys(), c, unknown);
}

UwbRangingOptions UwbRangingOptions::fromYamlFile(const std::string& path, std::vector<std::string>* unknown) {
  return core::parseYamlFile(path, [&](const YAML::Node& root) { return fromYaml(root, unknown); });
}

std::string UwbRangingOptions::validate() const {
  const auto bad = core::badValue;
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  auto unit = [](double v) { return v > 0.0 && v <= 1.0; };
  if (!positive(rhf.resolution)) return bad("grid_resolution", rhf.resolution, "finite and > 0");
  if (!(rhf.size_x >= rhf.resolution) || !std::isfinite(rhf.size_x))
    return bad("grid_size_x", rhf.size_x, "finite and >= grid_resolution");
  if (!(rhf.size_y >= rhf.resolution) || !std::isfinite(rhf.size_y))
    return bad("grid_size_y", rhf.size_y, "finite and >= grid_resolution");
  if (!(rhf.max_speed >= 0.0) || !std::isfinite(rhf.max_speed)) return bad("max_speed", rhf.max_speed, "finite and >= 0");
  if (!(rhf.p_threshold >= 0.0 && rhf.p_threshold < 1.0)) return bad("p_threshold", rhf.p_threshold, "in [0, 1)");
  if (!unit(rhf.p_min_uwb)) return bad("p_min_uwb", rhf.p_min_uwb, "in (0, 1]");
  if (!unit(rhf.p_min_cam)) return bad("p_min_cam", rhf.p_min_cam, "in (0, 1]");
  if (!unit(rhf.p_min_obs)) return bad("p_min_obs", rhf.p_min_obs, "in (0, 1]");
  if (!unit(rhf.p_min_inov)) return bad("p_min_inov", rhf.p_min_inov, "in (0, 1]");
  if (!positive(rhf.default_range_sigma)) return bad("default_range_sigma", rhf.default_range_sigma, "finite and > 0");
  if (!positive(rhf.default_bearing_sigma)) return bad("bearing_sigma", rhf.default_bearing_sigma, "finite and > 0");
  if (!(rhf.output_threshold >= 0.0 && rhf.output_threshold <= 1.0))
    return bad("output_threshold", rhf.output_threshold, "in [0, 1]");
  if (!(rhf.camera_gate >= 0.0 && rhf.camera_gate <= 1.0)) return bad("camera_gate", rhf.camera_gate, "in [0, 1]");
  if (!positive(max_range)) return bad("max_range", max_range, "finite and > 0");
  if (!(batch_window >= 0.0) || !std::isfinite(batch_window)) return bad("batch_window", batch_window, "finite and >= 0");
  if (!(bearing_max_age >= 0.0) || !std::isfinite(bearing_max_age))
    return bad("bearing_max_age", bearing_max_age, "finite and >= 0");
  if (pdoa_mode != "ignore" && pdoa_mode != "bearing" && pdoa_mode != "direct")
    return "pdoa_mode = " + pdoa_mode + ": must be ignore, bearing or direct";
  if (!positive(pdoa_angle_sigma)) return bad("pdoa_angle_sigma", pdoa_angle_sigma, "finite and > 0");
  if (!positive(min_sigma)) return bad("min_sigma", min_sigma, "finite and > 0");
  if (!positive(cutoff_sigmas)) return bad("cutoff_sigmas", cutoff_sigmas, "finite and > 0");
  if (!positive(reset_after)) return bad("reset_after", reset_after, "finite and > 0");
  if (!positive(max_output_sigma)) return bad("max_output_sigma", max_output_sigma, "finite and > 0");
  return "";
}

UwbRanging::UwbRanging(core::PickerRegistry registry, std::shared_ptr<const topology::TopologicalMap> map,
                       UwbRangingOptions options)
    : registry_(std::move(registry)), map_(std::move(map)), options_(std::move(options)) {
  if (!map_) throw std::invalid_argument("UwbRanging: no map");
  const std::string problem = options_.validate();
  if (!problem.empty()) throw std::invalid_argument("UwbRanging: " + problem);
}

const RangeHistogramFilter* UwbRanging::filter(const std::string& tag_id) const {
  auto it = tags_.find(tag_id);
  return (it == tags_.end() || !it->second.filter.initialised()) ? nullptr : &it->second.filter;
}

UwbRejection UwbRanging::addRange(const UwbRangeInput& in, const Eigen::Isometry2d& robot_pose,
                                  std::vector<core::Observation>* out, std::string* reason) {
  ++counters_.received;
  auto reject = [&](UwbRejection r, const std::string& why, std::size_t& counter) {
    ++counter;
    if (reason) *reason = why;
    return r;
  };
  if (!std::isfinite(in.stamp) || !std::isfinite(in.range) || !std::isfinite(in.variance) ||
      !in.anchor_in_robot.matrix().allFinite() || !robot_pose.matrix().allFinite() ||
      (in.pdoa_angle && !std::isfinite(*in.pdoa_angle)))
    return reject(UwbRejection::kNotFinite, "stamp, range, variance, angle or pose is NaN/Inf", counters_.not_finite);
  const std::optional<std::string> picker = registry_.pickerForUwbTag(in.tag_id);
  if (!picker) return reject(UwbRejection::kUnknownTag, "unknown tag '" + in.tag_id + "'", counters_.unknown_tag);
  if (in.range < 0.0) {
    std::ostringstream s;
    s << "negative range " << in.range << " m";
    return reject(UwbRejection::kNegativeRange, s.str(), counters_.negative_range);
  }
  if (in.range > options_.max_range) {
    std::ostringstream s;
    s << "range " << in.range << " m beyond max_range " << options_.max_range << " m";
    return reject(UwbRejection::kOutOfRange, s.str(), counters_.out_of_range);
  }
  auto it = tags_.find(in.tag_id);
  if (it == tags_.end()) it = tags_.emplace(in.tag_id, TagState(options_.rhf)).first;
  TagState& st = it->second;
  st.picker_id = *picker;
  if (in.stamp < st.last_stamp) {
    std::ostringstream s;
    s << "stamp " << in.stamp << " s is older than the tag's newest range (" << st.last_stamp << " s)";
    return reject(UwbRejection::kOutOfOrder, s.str(), counters_.out_of_order);
  }
  ++counters_.accepted;
  st.last_stamp = in.stamp;
  newest_stamp_ = std::max(newest_stamp_, in.stamp);
  if (st.batch && (in.stamp - st.batch->first_stamp > options_.batch_window ||
                   std::find(st.batch->anchors.begin(), st.batch->anchors.end(), in.frame_id) != st.batch->anchors.end()))
    processBatch(in.tag_id, st, out);

  const double variance = in.variance > 0.0 ? in.variance : options_.rhf.default_range_sigma * options_.rhf.default_range_sigma;
  const double anchor_yaw = std::atan2(in.anchor_in_robot.linear()(1, 0), in.anchor_in_robot.linear()(0, 0));
  if (in.pdoa_angle && options_.pdoa_mode == "direct") {
    // Periotto and Sartori: range + angle -> relative position in the anchor frame -> map frame.
    const Eigen::Isometry2d anchor_in_map = robot_pose * in.anchor_in_robot;
    const Eigen::Vector2d p = anchor_in_map * relativePositionFromAngle(in.range, *in.pdoa_angle);
    const Eigen::Matrix2d c_anchor =
        relativePositionCovariance(in.range, *in.pdoa_angle, variance, options_.pdoa_angle_sigma);
    const Eigen::Matrix2d c = anchor_in_map.linear() * c_anchor * anchor_in_map.linear().transpose();
    if (out) out->push_back(makeObservation(*picker, in.robot_id, in.stamp, p, c));
    ++counters_.observations;
    return UwbRejection::kNone;
  }
  if (!st.batch) {
    st.batch = Batch();
    st.batch->first_stamp = in.stamp;
  }
  Batch& b = *st.batch;
  b.last_stamp = in.stamp;
  b.robot_id = in.robot_id;
  b.robot_pose = robot_pose;
  b.anchors.push_back(in.frame_id);
  b.ranges.push_back({in.anchor_in_robot.translation(), in.range, variance});
  if (in.pdoa_angle && options_.pdoa_mode == "bearing")
    b.pdoa_bearings.push_back({in.anchor_in_robot.translation(), *in.pdoa_angle + anchor_yaw, options_.pdoa_angle_sigma});
  return UwbRejection::kNone;
}

void UwbRanging::addBearings(const CameraBearings& bearings) {
  if (!std::isfinite(bearings.stamp)) return;
  bearings_.push_back(bearings);
  counters_.bearings += bearings.bearings.size();
  // Keep the list short: drop sets far older than the newest one.
  const double newest = bearings.stamp;
  bearings_.erase(std::remove_if(bearings_.begin(), bearings_.end(),
                                 [&](const CameraBearings& c) { return c.stamp < newest - 4.0 * options_.bearing_max_age; }),
                  bearings_.end());
}

void UwbRanging::flush(double now, std::vector<core::Observation>* out) {
  for (auto& [tag, st] : tags_)
    if (st.batch && now - st.batch->first_stamp > options_.batch_window) processBatch(tag, st, out);
  // A tag not ranged for reset_after s (by the newest range's stamp) would restart from the uniform prior
  // anyway: its grids (~6 MB at the default 20 m x 20 m, 5 cm) are freed, so memory grows with the tags in
  // range, not with every tag ever seen (a 30-picker soak: 180 MB per robot before).
  for (auto it = tags_.begin(); it != tags_.end();)
    it = !it->second.batch && newest_stamp_ - it->second.last_stamp > options_.reset_after ? tags_.erase(it)
                                                                                           : std::next(it);
}

void UwbRanging::processBatch(const std::string& tag, TagState& st, std::vector<core::Observation>* out) {
  Batch b = std::move(*st.batch);
  st.batch.reset();
  (void)tag;
  if (st.filter.initialised() && b.last_stamp - st.filter.lastStamp() > options_.reset_after) st.filter.reset();
  std::vector<BearingMeasurement> bearings = b.pdoa_bearings;
  // Camera bearings: only the set nearest in time within bearing_max_age (one image per camera frame).
  const CameraBearings* best = nullptr;
  for (const CameraBearings& c : bearings_) {
    const double age = std::abs(b.last_stamp - c.stamp);
    if (age <= options_.bearing_max_age && (!best || age < std::abs(b.last_stamp - best->stamp))) best = &c;
  }
  if (best) bearings.insert(bearings.end(), best->bearings.begin(), best->bearings.end());
  std::optional<RhfEstimate> est = st.filter.update(b.last_stamp, b.ranges, bearings, b.robot_pose);
  if (!est) return;
  ++counters_.updates;
  const double max_var = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(est->covariance).eigenvalues().maxCoeff();
  if (est->touches_border || max_var > options_.max_output_sigma * options_.max_output_sigma) {
    ++counters_.suppressed;
    return;
  }
  if (out) out->push_back(makeObservation(st.picker_id, b.robot_id, b.last_stamp, est->position, est->covariance));
  ++counters_.observations;
}

core::Observation UwbRanging::makeObservation(const std::string& picker_id, const std::string& robot_id, double stamp,
                                              const Eigen::Vector2d& p_map, const Eigen::Matrix2d& c_map) const {
  core::Observation obs;
  obs.stamp = stamp;
  obs.sensor = options_.sensor;
  obs.robot_id = robot_id;
  obs.picker_id = picker_id;
  obs.identifying = true;
  core::GaussianLikelihoodOptions lo;
  lo.min_sigma = options_.min_sigma;
  lo.cutoff_sigmas = options_.cutoff_sigmas;
  core::setGaussianLikelihood(obs, *map_, p_map, c_map, lo);
  return obs;
}

void UwbRanging::setRegistry(core::PickerRegistry registry) {
  registry_ = std::move(registry);
  for (auto it = tags_.begin(); it != tags_.end();) {
    const std::optional<std::string> wearer = registry_.pickerForUwbTag(it->first);
    it = wearer && *wearer == it->second.picker_id ? std::next(it) : tags_.erase(it);
  }
}

}  // namespace sensors
}  // namespace picker_localisation
