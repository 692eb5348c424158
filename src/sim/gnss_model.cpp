#include "picker_localisation/sim/gnss_model.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace picker_localisation {
namespace sim {

MapDatum loadMapDatum(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": cannot read datum file (" + e.what() + ")");
  }
  if (root["datum"]) root = root["datum"];
  if (!root.IsMap()) throw std::runtime_error(path + ": datum file is not a mapping");
  MapDatum d;
  auto get = [&](const char* key, double& out, bool required) {
    if (!root[key]) {
      if (required) throw std::runtime_error(path + ": missing key '" + key + "'");
      return;
    }
    try {
      out = root[key].as<double>();
    } catch (const std::exception&) {
      throw std::runtime_error(path + ": key '" + key + "' is not a number");
    }
    if (!std::isfinite(out)) throw std::runtime_error(path + ": key '" + key + "' is not finite");
  };
  if (root["type"] && root["type"].as<std::string>() != "local_cartesian")
    throw std::runtime_error(path + ": datum type '" + root["type"].as<std::string>() +
                             "' is not supported by the simulator (use local_cartesian)");
  get("latitude", d.latitude, true);
  get("longitude", d.longitude, true);
  get("altitude", d.altitude, false);
  get("heading", d.heading_deg, false);  // older spelling
  get("heading_deg", d.heading_deg, false);
  if (std::abs(d.latitude) > 90.0 || std::abs(d.longitude) > 180.0)
    throw std::runtime_error(path + ": latitude/longitude out of range");
  return d;
}

MapProjection::MapProjection(const MapDatum& datum)
    : datum_(datum), proj_(datum.latitude, datum.longitude, datum.altitude) {
  const double h = datum.heading_deg * M_PI / 180.0;
  cos_h_ = std::cos(h);
  sin_h_ = std::sin(h);
}

void MapProjection::toGeodetic(const Eigen::Vector2d& map_xy, double z, double& lat, double& lon,
                               double& alt) const {
  // Map x axis points at `heading` counter-clockwise from East.
  const double east = cos_h_ * map_xy.x() - sin_h_ * map_xy.y();
  const double north = sin_h_ * map_xy.x() + cos_h_ * map_xy.y();
  proj_.Reverse(east, north, z, lat, lon, alt);
}

Eigen::Vector2d MapProjection::toMap(double lat, double lon, double alt) const {
  double east = 0.0, north = 0.0, up = 0.0;
  proj_.Forward(lat, lon, alt, east, north, up);
  return {cos_h_ * east + sin_h_ * north, -sin_h_ * east + cos_h_ * north};
}

GnssErrorModel::GnssErrorModel(const GnssNoiseParams& params, std::uint64_t rng_seed, double start_time)
    : params_(params), rng_(rng_seed), time_(start_time) {
  if (params_.offset_max < params_.offset_min || params_.blackout_max < params_.blackout_min ||
      !(params_.drift_tau > 0.0) || params_.drift_std < 0.0 || params_.white_std < 0.0)
    throw std::invalid_argument("GnssErrorModel: inconsistent noise parameters");
  std::uniform_real_distribution<double> off(params_.offset_min, params_.offset_max);
  offset_ = {off(rng_), off(rng_)};
  std::normal_distribution<double> n(0.0, 1.0);
  drift_ = {params_.drift_std * n(rng_), params_.drift_std * n(rng_)};
  if (params_.blackout_mean_interval > 0.0) {
    std::exponential_distribution<double> gap(1.0 / params_.blackout_mean_interval);
    next_transition_ = time_ + gap(rng_);
  } else {
    next_transition_ = std::numeric_limits<double>::infinity();
  }
}

void GnssErrorModel::advanceTo(double t) {
  if (t <= time_) return;
  // Drift: exact Ornstein-Uhlenbeck transition over the whole interval.
  const double a = std::exp(-(t - time_) / params_.drift_tau);
  const double s = params_.drift_std * std::sqrt(std::max(0.0, 1.0 - a * a));
  std::normal_distribution<double> n(0.0, 1.0);
  drift_ = a * drift_ + Eigen::Vector2d(s * n(rng_), s * n(rng_));
  // Blackouts: alternate exponential gaps and uniform durations; transitions inside (time_, t] take effect.
  while (next_transition_ <= t) {
    if (!blackout_) {
      blackout_ = true;
      blackout_start_ = next_transition_;
      std::uniform_real_distribution<double> dur(params_.blackout_min, params_.blackout_max);
      next_transition_ = blackout_start_ + dur(rng_);
    } else {
      blackout_ = false;
      blackout_log_.emplace_back(blackout_start_, next_transition_);
      std::exponential_distribution<double> gap(1.0 / params_.blackout_mean_interval);
      next_transition_ += gap(rng_);
    }
  }
  time_ = t;
}

std::optional<Eigen::Vector2d> GnssErrorModel::sample(double t) {
  advanceTo(t);
  std::normal_distribution<double> n(0.0, params_.white_std);
  // The white noise is drawn even in a blackout, so the stream does not depend on blackout timing.
  const Eigen::Vector2d white(n(rng_), n(rng_));
  if (blackout_) return std::nullopt;
  return offset_ + drift_ + white;
}

std::optional<GnssFix> makeGnssFix(GnssErrorModel& model, const MapProjection& projection,
                                   const GnssNoiseParams& params, double t, const Eigen::Vector2d& truth) {
  const auto err = model.sample(t);
  GnssFix fix;
  fix.stamp = t;
  fix.true_position = truth;
  if (!err) {
    if (!params.blackout_emits_no_fix) return std::nullopt;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    fix.status = -1;
    fix.latitude = fix.longitude = fix.altitude = nan;
    fix.covariance_type = 0;
    fix.in_blackout = true;
    fix.error = {nan, nan};
    return fix;
  }
  fix.error = *err;
  fix.status = 0;
  projection.toGeodetic(truth + *err, params.antenna_height, fix.latitude, fix.longitude, fix.altitude);
  const double v = params.reported_std * params.reported_std;
  fix.position_covariance = {v, 0, 0, 0, v, 0, 0, 0, 4.0 * v};
  fix.covariance_type = 2;
  return fix;
}

}  // namespace sim
}  // namespace picker_localisation
