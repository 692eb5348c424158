#include "picker_localisation/sensors_ranging/gnss_ingest.h"

#include <sstream>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/yaml_file.h"
#include "picker_localisation/core/yaml_keys.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace picker_localisation {
namespace sensors {

GnssIngestOptions GnssIngestOptions::fromYaml(const YAML::Node& y, std::vector<std::string>* unknown) {
  GnssIngestOptions o;
  if (!y || !y.IsMap()) return o;
  const std::string c = "gnss_ingest";
  core::readOption(y, c, "default_sigma", o.default_sigma);
  core::readOption(y, c, "min_sigma", o.min_sigma);
  core::readOption(y, c, "cutoff_sigmas", o.cutoff_sigmas);
  core::readOption(y, c, "max_speed", o.max_speed);
  core::readOption(y, c, "jump_gate_sigmas", o.jump_gate_sigmas);
  core::readOption(y, c, "blackout_timeout", o.blackout_timeout);
  core::readOption(y, c, "max_map_distance", o.max_map_distance);
  auto count = [&](const char* key, std::size_t& value) {
    long v = static_cast<long>(value);
    core::readOption(y, c, key, v);
    if (v < 0) throw std::runtime_error(c + ": " + key + " = " + std::to_string(v) + ": must be >= 0");
    value = static_cast<std::size_t>(v);
  };
  count("max_nodes", o.max_nodes);
  count("velocity_window", o.velocity_window);
  count("jump_reset_count", o.jump_reset_count);
  o.bias = GnssBiasOptions::fromYaml(y);
  o.association = PickerAssociationOptions::fromYaml(y);
  return core::checkOptions(o, y, yamlKeys(), c, unknown);
}

const std::vector<std::string>& GnssIngestOptions::yamlKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k{"default_sigma",    "min_sigma",       "cutoff_sigmas",    "max_nodes",
                               "velocity_window",  "max_speed",       "jump_gate_sigmas", "jump_reset_count",
                               "blackout_timeout", "max_map_distance"};
    k.insert(k.end(), GnssBiasOptions::yamlKeys().begin(), GnssBiasOptions::yamlKeys().end());
    k.insert(k.end(), PickerAssociationOptions::yamlKeys().begin(),
             PickerAssociationOptions::yamlKeys().end());
    return k;
  }();
  return keys;
}

GnssIngestOptions GnssIngestOptions::fromYamlFile(const std::string& path,
                                                  std::vector<std::string>* unknown) {
  return core::parseYamlFile(path, [&](const YAML::Node& root) { return fromYaml(root, unknown); });
}

std::string GnssIngestOptions::validate() const {
  const auto bad = core::badValue;
  if (!(default_sigma > 0.0) || !std::isfinite(default_sigma))
    return bad("default_sigma", default_sigma, "finite and > 0");
  if (!(min_sigma > 0.0) || !std::isfinite(min_sigma)) return bad("min_sigma", min_sigma, "finite and > 0");
  if (!(cutoff_sigmas > 0.0)) return bad("cutoff_sigmas", cutoff_sigmas, "> 0");
  if (!(max_speed > 0.0)) return bad("max_speed", max_speed, "> 0");
  if (!(jump_gate_sigmas >= 0.0)) return bad("jump_gate_sigmas", jump_gate_sigmas, ">= 0");
  if (!(blackout_timeout > 0.0)) return bad("blackout_timeout", blackout_timeout, "> 0");
  if (!(max_map_distance >= 0.0)) return bad("max_map_distance", max_map_distance, ">= 0 (0: no limit)");
  std::string problem = bias.validate();
  if (problem.empty()) problem = association.validate();
  return problem;
}

PickerAssociationOptions PickerAssociationOptions::fromYaml(const YAML::Node& y) {
  PickerAssociationOptions o;
  if (!y || !y.IsMap()) return o;
  const std::string c = "gnss_ingest";
  core::readOption(y, c, "associate_people", o.enabled);
  core::readOption(y, c, "association_clutter_density", o.clutter_density);
  core::readOption(y, c, "association_min_probability", o.min_probability);
  core::readOption(y, c, "association_belief_weight", o.belief_weight);
  core::readOption(y, c, "association_belief_sigma", o.belief_sigma);
  core::readOption(y, c, "association_max_fix_age", o.max_fix_age);
  core::readOption(y, c, "association_speed", o.speed);
  core::readOption(y, c, "association_max_belief_age", o.max_belief_age);
  core::readOption(y, c, "association_belief_lag", o.belief_lag);
  core::readOption(y, c, "association_sighting_min_probability", o.sighting_min_probability);
  core::readOption(y, c, "association_weigh_sightings", o.weigh_sightings);
  core::readOption(y, c, "association_min_candidate_probability", o.min_candidate_probability);
  core::readOption(y, c, "association_identity_sensors", o.identity_sensors);
  core::readOption(y, c, "association_identity_window", o.identity_window);
  core::readOption(y, c, "association_identity_floor", o.identity_floor);
  const std::string problem = o.validate();
  if (!problem.empty()) throw std::runtime_error(c + ": " + problem);
  return o;
}

const std::vector<std::string>& PickerAssociationOptions::yamlKeys() {
  static const std::vector<std::string> keys = {"associate_people",
                                                "association_clutter_density",
                                                "association_min_probability",
                                                "association_belief_weight",
                                                "association_belief_sigma",
                                                "association_max_fix_age",
                                                "association_speed",
                                                "association_max_belief_age",
                                                "association_belief_lag",
                                                "association_sighting_min_probability",
                                                "association_weigh_sightings",
                                                "association_min_candidate_probability",
                                                "association_identity_sensors",
                                                "association_identity_window",
                                                "association_identity_floor"};
  return keys;
}

std::string PickerAssociationOptions::validate() const {
  const auto bad = core::badValue;
  if (!(clutter_density > 0.0) || !std::isfinite(clutter_density))
    return bad("association_clutter_density", clutter_density, "finite and > 0");
  if (!(min_probability > 0.5 && min_probability <= 1.0))
    return bad("association_min_probability", min_probability, "in (0.5, 1]");
  if (!(sighting_min_probability >= 0.0 && sighting_min_probability <= 1.0))
    return bad("association_sighting_min_probability", sighting_min_probability, "in [0, 1]");
  if (!(min_candidate_probability >= 0.0 && min_candidate_probability < min_probability))
    return bad("association_min_candidate_probability", min_candidate_probability,
               "in [0, association_min_probability)");
  if (!(belief_weight >= 0.0 && belief_weight <= 1.0))
    return bad("association_belief_weight", belief_weight, "in [0, 1]");
  if (!(belief_sigma > 0.0) || !std::isfinite(belief_sigma))
    return bad("association_belief_sigma", belief_sigma, "finite and > 0");
  if (!(max_fix_age > 0.0)) return bad("association_max_fix_age", max_fix_age, "> 0");
  if (!(speed >= 0.0) || !std::isfinite(speed)) return bad("association_speed", speed, "finite and >= 0");
  if (!(max_belief_age > 0.0)) return bad("association_max_belief_age", max_belief_age, "> 0");
  if (!(belief_lag >= 0.0) || !std::isfinite(belief_lag))
    return bad("association_belief_lag", belief_lag, "finite and >= 0");
  if (!(identity_window > 0.0) || !std::isfinite(identity_window))
    return bad("association_identity_window", identity_window, "finite and > 0");
  if (!(identity_floor > 0.0 && identity_floor <= 1.0))
    return bad("association_identity_floor", identity_floor, "in (0, 1]");
  return "";
}

bool PickerAssociationOptions::isIdentitySensor(const std::string& sensor) const {
  return std::find(identity_sensors.begin(), identity_sensors.end(), sensor) != identity_sensors.end();
}

const char* toString(GnssRejection r) {
  switch (r) {
    case GnssRejection::kNone:
      return "accepted";
    case GnssRejection::kNoFix:
      return "no_fix";
    case GnssRejection::kNotFinite:
      return "not_finite";
    case GnssRejection::kNegativeCovariance:
      return "negative_covariance";
    case GnssRejection::kOutOfOrder:
      return "out_of_order";
    case GnssRejection::kImpossibleJump:
      return "impossible_jump";
    case GnssRejection::kOffMap:
      return "off_map";
  }
  return "unknown";
}

GnssIngest::GnssIngest(std::string picker_id, std::shared_ptr<const topology::TopologicalMap> map,
                       core::GeodeticDatum datum, GnssIngestOptions options)
    : picker_id_(std::move(picker_id)),
      map_(std::move(map)),
      datum_(std::move(datum)),
      options_(options),
      bias_(options_.bias) {
  if (!map_) throw std::invalid_argument("GnssIngest: no map");
}

bool GnssIngest::inBlackout(double now) const {
  return last_ && now - last_->stamp > options_.blackout_timeout;
}

double GnssIngest::ageOfLastFix(double now) const {
  return last_ ? now - last_->stamp : std::numeric_limits<double>::infinity();
}

// The fix's horizontal covariance (the ENU east-north block of the row-major 3x3; default_sigma when the unit
// reports none). False with the rejection and its reason when it is unusable.
bool GnssIngest::horizontalCovariance(const core::GnssFix& fix, Eigen::Matrix2d& c_en,
                                      GnssRejection& rejection, std::string& why) const {
  auto fail = [&](GnssRejection r, const char* reason) {
    rejection = r;
    why = reason;
    return false;
  };
  if (fix.covariance_type <= 0) {
    c_en = Eigen::Matrix2d::Identity() * options_.default_sigma * options_.default_sigma;
  } else {
    c_en << fix.position_covariance[0], fix.position_covariance[1], fix.position_covariance[3],
        fix.position_covariance[4];
    if (!c_en.allFinite()) return fail(GnssRejection::kNotFinite, "covariance is NaN/Inf");
    if (c_en(0, 0) < 0.0 || c_en(1, 1) < 0.0)
      return fail(GnssRejection::kNegativeCovariance, "negative variance in the covariance");
    // DIAGONAL_KNOWN: off-diagonal terms are meaningless by definition.
    if (fix.covariance_type == 2) c_en(0, 1) = c_en(1, 0) = 0.0;
    c_en = 0.5 * (c_en + c_en.transpose());
    if (!core::isCovariance2d(c_en))
      return fail(GnssRejection::kNegativeCovariance, "horizontal covariance is not positive semi-definite");
  }
  return true;
}

// The gate against impossible jumps from the last accepted fix (Mahalanobis distance with the two fixes'
// covariances and max_speed * dt of motion). A jump that persists for jump_reset_count fixes re-anchors
// the gate (the reference was the outlier, or the picker really moved). False with the reason when the fix
// fails.
bool GnssIngest::passesJumpGate(const Eigen::Vector2d& p, const Eigen::Matrix2d& c_map, double dt,
                                std::string& why) {
  if (!(options_.jump_gate_sigmas > 0.0)) return true;
  const Eigen::Vector2d d = p - last_->position;
  const double reach = options_.max_speed * dt;
  const Eigen::Matrix2d c = last_->covariance + c_map + reach * reach * Eigen::Matrix2d::Identity();
  const double m2 = d.dot(c.inverse() * d);
  if (m2 <= options_.jump_gate_sigmas * options_.jump_gate_sigmas) return true;
  ++consecutive_jumps_;
  if (consecutive_jumps_ < options_.jump_reset_count || options_.jump_reset_count == 0) {
    std::ostringstream s;
    s << "jump of " << d.norm() << " m in " << dt << " s fails the gate (Mahalanobis " << std::sqrt(m2)
      << " > " << options_.jump_gate_sigmas << ")";
    why = s.str();
    return false;
  }
  ++counters_.gate_resets;
  window_.clear();
  return true;
}

// The identifying observation of an accepted fix at map position p: bias removed when the estimate is usable.
core::Observation GnssIngest::observationOf(double stamp, const Eigen::Vector2d& p,
                                            const Eigen::Matrix2d& c_map, bool* bias_corrected) const {
  core::Observation obs;
  obs.stamp = stamp;
  obs.sensor = options_.sensor;
  obs.picker_id = picker_id_;
  obs.identifying = true;
  core::GaussianLikelihoodOptions lo = options_.likelihoodOptions();
  if (bias_.usable(stamp)) {
    // Bias removed (Khan et al. 2020, Sec. VI): the fix minus the estimate, with the estimate's own
    // uncertainty in place of the unit's reported one (which is mostly the bias itself).
    const double r2 = options_.bias.residual_std * options_.bias.residual_std;
    lo.min_sigma = options_.bias.min_sigma;
    const Eigen::Vector2d corrected = p - bias_.bias(stamp);
    obs.position = corrected;
    obs.position_covariance =
        options_.bias.error_inflation * bias_.covariance(stamp) + r2 * Eigen::Matrix2d::Identity();
    *bias_corrected = true;
  } else {
    obs.position = p;
    obs.position_covariance = c_map;
  }
  // What was removed and how well it is known: the TPF's per-particle bias state starts from it.
  obs.bias_removed = bias_.applied(stamp);
  obs.bias_covariance = bias_.appliedCovariance(stamp);
  obs.bias_drift_rate = options_.bias.driftRate();
  core::setGaussianLikelihood(obs, *map_, *obs.position, obs.position_covariance, lo);
  if (options_.velocity_window >= 2 && window_.size() >= 2) {
    const double span = window_.back().stamp - window_.front().stamp;
    if (span > 0.0) obs.velocity = (window_.back().position - window_.front().position) / span;
  }
  return obs;
}

GnssResult GnssIngest::process(const core::GnssFix& fix) {
  GnssResult result;
  ++counters_.received;
  auto reject = [&](GnssRejection r, const std::string& why, std::size_t& counter) {
    result.rejection = r;
    result.reason = why;
    ++counter;
    return result;
  };
  // NO_FIX first: receivers commonly send NaN positions with it, and "no fix" is the better reason.
  if (fix.status < 0) return reject(GnssRejection::kNoFix, "status NO_FIX", counters_.no_fix);
  if (!std::isfinite(fix.stamp) || !std::isfinite(fix.latitude) || !std::isfinite(fix.longitude))
    return reject(GnssRejection::kNotFinite, "stamp, latitude or longitude is NaN/Inf", counters_.not_finite);
  if (std::abs(fix.latitude) > 90.0 || std::abs(fix.longitude) > 180.0)
    return reject(GnssRejection::kNotFinite, "latitude / longitude out of range", counters_.not_finite);

  Eigen::Matrix2d c_en;
  GnssRejection bad_covariance = GnssRejection::kNone;
  std::string why;
  if (!horizontalCovariance(fix, c_en, bad_covariance, why))
    return reject(
        bad_covariance, why,
        bad_covariance == GnssRejection::kNotFinite ? counters_.not_finite : counters_.negative_covariance);
  // Floor each axis (the likelihood also floors the eigenvalues).
  const double floor = options_.min_sigma * options_.min_sigma;
  c_en(0, 0) = std::max(c_en(0, 0), floor);
  c_en(1, 1) = std::max(c_en(1, 1), floor);
  const Eigen::Matrix2d c_map = datum_.enuToMap(c_en);
  const Eigen::Vector2d p = datum_.toMap(fix.latitude, fix.longitude, fix.altitude);
  if (!p.allFinite())
    return reject(GnssRejection::kNotFinite, "projection gave NaN/Inf", counters_.not_finite);
  result.position = p;

  if (last_ && fix.stamp <= last_->stamp) {
    std::ostringstream s;
    s << "stamp " << fix.stamp << " s is not after the last accepted fix (" << last_->stamp << " s)";
    return reject(GnssRejection::kOutOfOrder, s.str(), counters_.out_of_order);
  }

  if (double off = 0.0; options_.farFromMap(*map_, p, &off)) {
    std::ostringstream s;
    s << "fix " << off << " m from the nearest map node (max_map_distance " << options_.max_map_distance
      << " m)";
    return reject(GnssRejection::kOffMap, s.str(), counters_.off_map);
  }

  bool after_blackout = false;
  if (last_) {
    const double dt = fix.stamp - last_->stamp;
    after_blackout = dt > options_.blackout_timeout;
    if (!after_blackout && !passesJumpGate(p, c_map, dt, why))
      return reject(GnssRejection::kImpossibleJump, why, counters_.impossible_jump);
  }
  consecutive_jumps_ = 0;
  if (after_blackout) {
    result.blackout_ended = fix.stamp - last_->stamp;
    ++counters_.blackouts;
    counters_.longest_blackout = std::max(counters_.longest_blackout, result.blackout_ended);
    window_.clear();  // the velocity must not span the gap
  }

  last_ = Accepted{fix.stamp, p, c_map};
  window_.push_back(*last_);
  while (window_.size() > std::max<std::size_t>(options_.velocity_window, 1)) window_.pop_front();
  recent_.push_back(*last_);
  while (recent_.size() > kRecentFixes) recent_.pop_front();
  ++counters_.accepted;

  result.observation = observationOf(fix.stamp, p, c_map, &result.bias_corrected);
  return result;
}

BiasUpdate GnssIngest::addSighting(double stamp, const Eigen::Vector2d& position,
                                   const Eigen::Matrix2d& covariance, double probability) {
  BiasUpdate u;
  if (!options_.bias.enabled) {
    u.reason = "bias estimation is disabled";
    return u;
  }
  const Accepted* nearest = nullptr;
  for (const Accepted& f : recent_)
    if (!nearest || std::abs(f.stamp - stamp) < std::abs(nearest->stamp - stamp)) nearest = &f;
  if (!nearest || std::abs(nearest->stamp - stamp) > options_.bias.pairing_gap) {
    u.reason = "no fix within bias_pairing_gap of the sighting";
    return u;
  }
  const double gap = std::abs(nearest->stamp - stamp);
  const double r = options_.bias.residual_std, m = options_.bias.pairing_speed * gap;
  const Eigen::Matrix2d R = covariance + (r * r + m * m) * Eigen::Matrix2d::Identity();
  return bias_.update(stamp, nearest->position - position, R, probability);
}

GnssIngest::Prediction GnssIngest::predictPosition(double t, double speed, double max_age) const {
  Prediction pr;
  if (!last_ || std::abs(t - last_->stamp) > max_age) return pr;
  pr.valid = true;
  const double r = options_.bias.residual_std, m = speed * std::abs(t - last_->stamp);
  // Before any sighting (or with the estimate disabled) the bias is unknown: zero, with its prior covariance.
  pr.mean = last_->position - bias_.applied(t);
  pr.covariance = bias_.appliedCovariance(t) + (r * r + m * m) * Eigen::Matrix2d::Identity();
  return pr;
}

void GnssIngest::setMap(std::shared_ptr<const topology::TopologicalMap> map, const core::GeodeticDatum& datum,
                        bool datum_moved) {
  if (!map) return;
  map_ = std::move(map);
  if (!datum_moved) return;
  datum_ = datum;
  window_.clear();
  recent_.clear();
  last_.reset();
  consecutive_jumps_ = 0;
}

}  // namespace sensors
}  // namespace picker_localisation
