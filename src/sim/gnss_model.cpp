#include "picker_localisation/sim/gnss_model.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace picker_localisation {
namespace sim {

core::DatumConfig riseholmeDatum() {
  core::DatumConfig d;  // Riseholme campus, Lincoln (UK), approximately (as config/datum.yaml)
  d.latitude = 53.268;
  d.longitude = -0.524;
  return d;
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
      if (params_.redraw_after_blackout) {
        std::normal_distribution<double> stationary(0.0, params_.drift_std);
        drift_ = Eigen::Vector2d(stationary(rng_), stationary(rng_));
      }
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

std::optional<GnssFixWithTruth> makeGnssFix(GnssErrorModel& model, const core::GeodeticDatum& datum,
                                            const GnssNoiseParams& params, double t,
                                            const Eigen::Vector2d& truth) {
  const auto err = model.sample(t);
  GnssFixWithTruth fix;
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
  datum.toGeodetic(truth + *err, params.antenna_height, fix.latitude, fix.longitude, fix.altitude);
  const double v = params.reported_std * params.reported_std;
  fix.position_covariance = {v, 0, 0, 0, v, 0, 0, 0, 4.0 * v};
  fix.covariance_type = 2;
  return fix;
}

}  // namespace sim
}  // namespace picker_localisation
