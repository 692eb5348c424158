// Low-cost GNSS error model of Navigate-and-Seek Table I; fixes in WGS84 through the map's
// core::GeodeticDatum. ROS-free.
//
// Error added to the true map position p at time t, per axis (x, y of the map frame):
//   fix = p + offset + drift(t) + white(t)
//  - offset: constant per picker, each axis drawn once from U(offset_min, offset_max) = U(0, 3.5) m (Table I
//    gps_offset; taken literally: non-negative, the same sign convention on both axes).
//  - white: N(0, white_std^2) per axis and fix, white_std = 0.1 m (Table I gps_var = 0.1 m read as the std).
//  - drift: a first-order Gauss-Markov (Ornstein-Uhlenbeck) process per axis with stationary distribution
//    N(0, drift_std^2), drift_std = 2.5 m (Table I gps_drift), correlation time drift_tau (default 300 s),
//    started from its stationary distribution. Exact discretisation over dt:
//      d <- a d + sqrt(1 - a^2) drift_std n,  a = exp(-dt / drift_tau),  n ~ N(0, 1).
//  - blackouts (Table I gps_off): onsets form a Poisson process of rate 1 / blackout_mean_interval
//    (default one per 600 s of non-blackout time); each lasts U(blackout_min, blackout_max) = U(30, 60) s.
//    During a blackout the fix has status NO_FIX and NaN lat/lon/alt (or no fix at all,
//    `blackout_emits_no_fix` false). The drift keeps evolving through a blackout, or (redraw_after_blackout)
//    is drawn afresh from its stationary distribution when the blackout ends.
// The reported covariance is diagonal with reported_std^2 on east/north and (2 reported_std)^2 on up.
#pragma once

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/sim/sim_types.h"

#include <optional>
#include <random>
#include <string>

namespace picker_localisation {
namespace sim {

// Where the map frame sits on the Earth: core::GeodeticDatum (config/datum.yaml, or the `datum:` section of
// config/sim.yaml with the same keys). The simulator's default is Riseholme, as config/datum.yaml.
core::DatumConfig riseholmeDatum();

struct GnssNoiseParams {
  double offset_min = 0.0;                // m, per-axis constant offset ~ U(offset_min, offset_max)
  double offset_max = 3.5;                // m
  double white_std = 0.1;                 // m, per-axis white noise std
  double drift_std = 2.5;                 // m, stationary std of the Gauss-Markov drift per axis
  double drift_tau = 300.0;               // s, correlation time of the drift
  double blackout_mean_interval = 600.0;  // s, mean non-blackout time between blackout onsets
  double blackout_min = 30.0;             // s, blackout duration ~ U(blackout_min, blackout_max)
  double blackout_max = 60.0;             // s
  bool blackout_emits_no_fix = true;      // during a blackout: a NO_FIX message (true) or nothing (false)
  // At the end of a blackout the drift is drawn afresh from its stationary distribution (a phone that lost
  // its fix under canopy comes back with an unrelated error) instead of continuing where it was.
  bool redraw_after_blackout = false;
  double rate = 1.0;                      // Hz, fixes per second
  double reported_std = 3.0;    // m, std written into the fix's covariance (what a phone would report)
  double antenna_height = 1.0;  // m above the map plane (altitude = datum altitude + this)
};

// The error process of one picker's GNSS unit. Owns its generator.
class GnssErrorModel {
 public:
  GnssErrorModel(const GnssNoiseParams& params, std::uint64_t rng_seed, double start_time = 0.0);
  // Advances the drift and the blackout process to time t (>= time()); returns the error (offset + drift +
  // fresh white noise) at t, or nullopt while in a blackout.
  std::optional<Eigen::Vector2d> sample(double t);
  // Advances the state to t without producing a sample.
  void advanceTo(double t);
  double time() const { return time_; }
  bool inBlackout() const { return blackout_; }
  const Eigen::Vector2d& offset() const { return offset_; }
  const Eigen::Vector2d& drift() const { return drift_; }
  // Completed blackouts so far as (start, end) times, for tests.
  const std::vector<std::pair<double, double>>& blackouts() const { return blackout_log_; }

 private:
  GnssNoiseParams params_;
  std::mt19937_64 rng_;
  double time_ = 0.0;
  Eigen::Vector2d offset_{0.0, 0.0}, drift_{0.0, 0.0};
  bool blackout_ = false;
  double next_transition_ = 0.0;  // end of the blackout, or the next onset
  double blackout_start_ = 0.0;
  std::vector<std::pair<double, double>> blackout_log_;
};

// Builds the fix a picker's unit reports at time t for true map position `truth` (error from `model`).
// Returns nullopt during a blackout when params.blackout_emits_no_fix is false.
std::optional<GnssFixWithTruth> makeGnssFix(GnssErrorModel& model, const core::GeodeticDatum& datum,
                                            const GnssNoiseParams& params, double t,
                                            const Eigen::Vector2d& truth);

}  // namespace sim
}  // namespace picker_localisation
