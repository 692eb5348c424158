// Online estimate of one GNSS device's bias (Khan et al. 2020 Sec. VI: "estimate the GNSS bias from the
// robot's own sensing"). ROS-free.
//
// Why a state and not a per-fix offset: a phone or IoT unit is wrong by an almost constant offset plus a slow
// drift (Table I: offset U(0, 3.5) m per axis, drift N(0, 2.5) m), while lanes are 1.3-1.5 m apart. A fix
// alone can never name the lane; the difference between the fix and where a robot *sees* the picker measures
// the bias, and the bias stays informative for tens of seconds.
//
// Model (per map axis, x and y independent in the prior): bias b = c + d with
//   c  constant offset,          prior N(0, offset_std^2)   (zero mean: the sign of a unit's offset is unknown)
//   d  Ornstein-Uhlenbeck drift, stationary N(0, drift_std^2), correlation time drift_tau:
//      d(t + dt) = a d(t) + w,  a = exp(-dt / drift_tau),  w ~ N(0, drift_std^2 (1 - a^2))  (exact transition)
// A four-state Kalman filter (x = [c_x, c_y, d_x, d_y]) is updated with measurements y = b + v, v ~ N(0, R),
// where y = (raw fix) - (sighted position). Prediction decays d and leaves c: long after the last sighting the
// estimate tends to the learned constant offset c with variance P_c + drift_std^2, so an old estimate is still
// used but with an honest covariance. Why not bias hypotheses on the particles: the bias is a property of the
// device (shared by every robot's sightings and every tracker), it needs metric sightings the particles do not
// carry, and a 4x4 filter costs nothing next to 300 particles x 2 more dimensions.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

namespace picker_localisation {
namespace sensors {

struct GnssBiasOptions {
  bool enabled = true;         // estimate and remove the bias (false: fixes are used as they come)
  double offset_std = 2.0;     // m, prior std of the constant offset per axis (Table I U(0, 3.5): RMS 2.0)
  double drift_std = 2.5;      // m, stationary std of the drift per axis (Table I gps_drift)
  double drift_tau = 300.0;    // s, correlation time of the drift
  double residual_std = 0.5;   // m, per-axis noise of a fix once the bias is removed (white noise of the unit)
  double min_sigma = 0.5;      // m, floor on each std of a bias-corrected fix's likelihood (replaces min_sigma)
  double pairing_gap = 2.0;    // s, a sighting pairs with the raw fix nearest in time, at most this far away
  double pairing_speed = 1.0;  // m/s, picker motion between fix and sighting: adds (speed * gap)^2 to R
  double gate_sigmas = 3.5;    // a sighting whose innovation exceeds this Mahalanobis distance is refused
  double max_age = 600.0;      // s after the last sighting beyond which corrections stop (estimate = prior)
  // Recovery from a wrong estimate. A LiDAR person given to the wrong picker can pass the gate while the
  // estimate is still wide (the first sighting, or one after minutes unseen); the gate then refuses the right
  // sightings that follow, and the estimate stays off by the distance between the two people. When
  // restart_sightings refused sightings within restart_window s agree with each other (each within
  // gate_sigmas of the first, with both covariances and the drift between them) and no sighting was accepted
  // since the first of them, the estimate starts again from the prior with those sightings. 0: never.
  int restart_sightings = 3;
  double restart_window = 20.0;  // s
  // Every corrected fix carries the same estimate error, but the filter fuses fixes as independent: N fixes
  // would count that error N times too few. The estimate's covariance in a corrected fix's likelihood is
  // multiplied by this factor (1: as if independent).
  double error_inflation = 1.0;
  // Identifying observations of these sensors that carry a position (rfid: the antenna, read-disc covariance;
  // uwb: the Range Histogram Filter's estimate) are sightings too, besides the associated people. Default none:
  // measured with rfid (10 seeds, Table I GNSS) rfid_gnss fell from 0.227 to 0.057 right lane and
  // rfid_lidar_gnss from 0.729 to 0.571. A read puts the picker somewhere within ~4 m of the antenna, the same
  // somewhere for many consecutive reads, so the reads' errors are not independent and the estimate converges on
  // the wrong offset. uwb is not simulated in Table II (not measured).
  std::vector<std::string> sighting_sensors;

  // Keys bias_<name> (enabled: estimate_bias) of config/gnss_ingest.yaml; a bad value throws
  // std::runtime_error naming the key. Unknown keys are checked by GnssIngestOptions.
  static GnssBiasOptions fromYaml(const YAML::Node& node);
  static const std::vector<std::string>& yamlKeys();
  std::string validate() const;  // "" or "<key> = <value>: must be ..."
  // Covariance of the bias before any sighting: (offset_std^2 + drift_std^2) I.
  Eigen::Matrix2d priorCovariance() const;
  // Rate at which the drift's variance grows over short times, 2 drift_std^2 / drift_tau, m^2/s per axis.
  double driftRate() const { return 2.0 * drift_std * drift_std / drift_tau; }
  bool isSightingSensor(const std::string& sensor) const;  // sensor is in sighting_sensors
};

// The outcome of one sighting.
struct BiasUpdate {
  bool accepted = false;
  std::string reason;                       // why a sighting was refused (empty when accepted)
  Eigen::Vector2d innovation = Eigen::Vector2d::Zero();  // m, y - predicted bias
  double mahalanobis = 0.0;
};

class GnssBiasEstimator {
 public:
  explicit GnssBiasEstimator(GnssBiasOptions options = {});

  // Kalman update with a measured bias y (m, map frame) of covariance R at time t (s). Refused (state
  // unchanged) when t is before the last sighting, y/R not finite, or the innovation fails the gate.
  // `probability` < 1: the sighting is of this picker only with that probability (a people detection the
  // association named); the update is the probabilistic data association filter's for one validated
  // measurement (Bar-Shalom and Tse 1975): x += beta K nu, P -= beta K S K^T - beta (1 - beta) K nu nu^T K^T.
  BiasUpdate update(double t, const Eigen::Vector2d& measured_bias, const Eigen::Matrix2d& covariance,
                    double probability = 1.0);
  // Predicted bias and its covariance at time t (>= the last sighting; earlier t gives the state at it).
  Eigen::Vector2d bias(double t) const;
  Eigen::Matrix2d covariance(double t) const;
  // True after the first accepted sighting and while t - lastSighting() <= max_age.
  bool usable(double t) const;
  // What fixes at time t have removed and its uncertainty: bias(t) and covariance(t) while usable(t), else zero
  // and the prior covariance (the bias is unknown).
  Eigen::Vector2d applied(double t) const;
  Eigen::Matrix2d appliedCovariance(double t) const;
  bool sighted() const { return sightings_ > 0; }
  double lastSighting() const { return last_; }
  std::size_t sightings() const { return sightings_; }
  std::size_t refused() const { return refused_; }
  std::size_t restarts() const { return restarts_; }
  const GnssBiasOptions& options() const { return options_; }
  void reset();

 private:
  void predicted(double t, Eigen::Matrix<double, 4, 1>& x, Eigen::Matrix4d& P) const;
  GnssBiasOptions options_;
  Eigen::Matrix<double, 4, 1> x_;
  Eigen::Matrix4d P_;
  double last_ = 0.0;
  std::size_t sightings_ = 0, refused_ = 0;
  struct Refused {
    double t;
    Eigen::Vector2d y;
    Eigen::Matrix2d R;
  };
  std::vector<Refused> refused_recent_;  // since the last accepted sighting, within restart_window
  std::size_t restarts_ = 0;
  // The refused sightings agree: start again from the prior with them (restart_sightings).
  bool restartFromRefused();
};

}  // namespace sensors
}  // namespace picker_localisation
