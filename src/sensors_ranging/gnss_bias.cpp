#include "picker_localisation/sensors_ranging/gnss_bias.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace sensors {

GnssBiasOptions GnssBiasOptions::fromYaml(const YAML::Node& y) {
  GnssBiasOptions o;
  if (!y || !y.IsMap()) return o;
  const std::string c = "gnss_ingest";
  core::readOption(y, c, "estimate_bias", o.enabled);
  core::readOption(y, c, "bias_offset_std", o.offset_std);
  core::readOption(y, c, "bias_drift_std", o.drift_std);
  core::readOption(y, c, "bias_drift_tau", o.drift_tau);
  core::readOption(y, c, "bias_residual_std", o.residual_std);
  core::readOption(y, c, "bias_min_sigma", o.min_sigma);
  core::readOption(y, c, "bias_pairing_gap", o.pairing_gap);
  core::readOption(y, c, "bias_pairing_speed", o.pairing_speed);
  core::readOption(y, c, "bias_gate_sigmas", o.gate_sigmas);
  core::readOption(y, c, "bias_max_age", o.max_age);
  core::readOption(y, c, "bias_restart_sightings", o.restart_sightings);
  core::readOption(y, c, "bias_restart_window", o.restart_window);
  core::readOption(y, c, "bias_error_inflation", o.error_inflation);
  core::readOption(y, c, "bias_sighting_sensors", o.sighting_sensors);
  const std::string problem = o.validate();
  if (!problem.empty()) throw std::runtime_error(c + ": " + problem);
  return o;
}

const std::vector<std::string>& GnssBiasOptions::yamlKeys() {
  static const std::vector<std::string> keys = {
      "estimate_bias",        "bias_offset_std",      "bias_drift_std",         "bias_drift_tau",
      "bias_residual_std",    "bias_min_sigma",       "bias_pairing_gap",       "bias_pairing_speed",
      "bias_gate_sigmas",     "bias_max_age",         "bias_restart_sightings", "bias_restart_window",
      "bias_error_inflation", "bias_sighting_sensors"};
  return keys;
}

std::string GnssBiasOptions::validate() const {
  const auto bad = core::badValue;
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!(offset_std >= 0.0) || !std::isfinite(offset_std)) return bad("bias_offset_std", offset_std, "finite and >= 0");
  if (!(drift_std >= 0.0) || !std::isfinite(drift_std)) return bad("bias_drift_std", drift_std, "finite and >= 0");
  if (!(offset_std + drift_std > 0.0)) return bad("bias_offset_std", offset_std, "> 0 when bias_drift_std is 0");
  if (!positive(drift_tau)) return bad("bias_drift_tau", drift_tau, "finite and > 0");
  if (!positive(residual_std)) return bad("bias_residual_std", residual_std, "finite and > 0");
  if (!positive(min_sigma)) return bad("bias_min_sigma", min_sigma, "finite and > 0");
  if (!(pairing_gap >= 0.0) || !std::isfinite(pairing_gap)) return bad("bias_pairing_gap", pairing_gap, "finite and >= 0");
  if (!(pairing_speed >= 0.0) || !std::isfinite(pairing_speed))
    return bad("bias_pairing_speed", pairing_speed, "finite and >= 0");
  if (!positive(gate_sigmas)) return bad("bias_gate_sigmas", gate_sigmas, "finite and > 0");
  if (!(max_age > 0.0)) return bad("bias_max_age", max_age, "> 0");
  if (restart_sightings < 0 || restart_sightings > 100)
    return bad("bias_restart_sightings", restart_sightings, "in [0, 100]");
  if (!positive(restart_window)) return bad("bias_restart_window", restart_window, "finite and > 0");
  if (!(error_inflation >= 1.0) || !std::isfinite(error_inflation))
    return bad("bias_error_inflation", error_inflation, "finite and >= 1");
  return "";
}

Eigen::Matrix2d GnssBiasOptions::priorCovariance() const {
  return Eigen::Matrix2d::Identity() * (offset_std * offset_std + drift_std * drift_std);
}

bool GnssBiasOptions::isSightingSensor(const std::string& sensor) const {
  return std::find(sighting_sensors.begin(), sighting_sensors.end(), sensor) != sighting_sensors.end();
}

GnssBiasEstimator::GnssBiasEstimator(GnssBiasOptions options) : options_(options) {
  const std::string problem = options_.validate();
  if (!problem.empty()) throw std::invalid_argument("GnssBiasEstimator: " + problem);
  reset();
}

void GnssBiasEstimator::reset() {
  x_.setZero();
  P_.setZero();
  P_.topLeftCorner<2, 2>() = Eigen::Matrix2d::Identity() * options_.offset_std * options_.offset_std;
  P_.bottomRightCorner<2, 2>() = Eigen::Matrix2d::Identity() * options_.drift_std * options_.drift_std;
  last_ = 0.0;
  sightings_ = refused_ = 0;
  refused_recent_.clear();
  restarts_ = 0;
}

// Exact OU transition of the drift states; the offset states are constant.
void GnssBiasEstimator::predicted(double t, Eigen::Matrix<double, 4, 1>& x, Eigen::Matrix4d& P) const {
  x = x_;
  P = P_;
  if (!sighted() || !(t > last_)) return;  // before a sighting the prior is stationary
  const double a = std::exp(-(t - last_) / options_.drift_tau);
  Eigen::Matrix4d F = Eigen::Matrix4d::Identity();
  F.bottomRightCorner<2, 2>() *= a;
  Eigen::Matrix4d Q = Eigen::Matrix4d::Zero();
  Q.bottomRightCorner<2, 2>() =
      Eigen::Matrix2d::Identity() * options_.drift_std * options_.drift_std * (1.0 - a * a);
  x = F * x;
  P = F * P * F.transpose() + Q;
}

Eigen::Vector2d GnssBiasEstimator::bias(double t) const {
  Eigen::Matrix<double, 4, 1> x;
  Eigen::Matrix4d P;
  predicted(t, x, P);
  return x.head<2>() + x.tail<2>();  // b = c + d
}

Eigen::Matrix2d GnssBiasEstimator::covariance(double t) const {
  Eigen::Matrix<double, 4, 1> x;
  Eigen::Matrix4d P;
  predicted(t, x, P);
  // H P H^T with H = [I I].
  return P.topLeftCorner<2, 2>() + P.bottomRightCorner<2, 2>() + P.topRightCorner<2, 2>() +
         P.bottomLeftCorner<2, 2>();
}

bool GnssBiasEstimator::usable(double t) const {
  return options_.enabled && sighted() && t - last_ <= options_.max_age;
}

Eigen::Vector2d GnssBiasEstimator::applied(double t) const {
  return usable(t) ? bias(t) : Eigen::Vector2d::Zero();
}

Eigen::Matrix2d GnssBiasEstimator::appliedCovariance(double t) const {
  return usable(t) ? covariance(t) : options_.priorCovariance();
}

BiasUpdate GnssBiasEstimator::update(double t, const Eigen::Vector2d& y, const Eigen::Matrix2d& R,
                                     double probability) {
  BiasUpdate u;
  auto refuse = [&](const std::string& why) {
    u.reason = why;
    ++refused_;
    return u;
  };
  if (!std::isfinite(t) || !y.allFinite() || !R.allFinite()) return refuse("sighting is NaN/Inf");
  if (!(probability > 0.0 && probability <= 1.0)) return refuse("sighting probability is not in (0, 1]");
  if (sighted() && t < last_) return refuse("sighting is older than the last one used");
  Eigen::Matrix<double, 4, 1> x;
  Eigen::Matrix4d P;
  predicted(t, x, P);
  Eigen::Matrix<double, 2, 4> H;
  H << Eigen::Matrix2d::Identity(), Eigen::Matrix2d::Identity();
  const Eigen::Matrix2d S = H * P * H.transpose() + 0.5 * (R + R.transpose());
  if (!(S.determinant() > 0.0)) return refuse("innovation covariance is singular");
  const Eigen::Matrix2d S_inv = S.inverse();
  u.innovation = y - H * x;
  u.mahalanobis = std::sqrt(std::max(0.0, u.innovation.dot(S_inv * u.innovation)));
  if (u.mahalanobis > options_.gate_sigmas) {
    std::ostringstream s;
    s << "innovation " << u.innovation.norm() << " m fails the gate (Mahalanobis " << u.mahalanobis << " > "
      << options_.gate_sigmas << ")";
    if (options_.restart_sightings > 0) {
      refused_recent_.push_back({t, y, 0.5 * (R + R.transpose())});
      const double since = t - options_.restart_window;
      refused_recent_.erase(std::remove_if(refused_recent_.begin(), refused_recent_.end(),
                                           [since](const Refused& r) { return r.t < since; }),
                            refused_recent_.end());
      if (restartFromRefused()) {
        BiasUpdate restarted;
        restarted.accepted = true;
        restarted.innovation = u.innovation;
        restarted.mahalanobis = u.mahalanobis;
        restarted.reason =
            "restarted from " + std::to_string(options_.restart_sightings) + " refused sightings that agree";
        return restarted;
      }
    }
    return refuse(s.str());
  }
  refused_recent_.clear();
  const Eigen::Matrix<double, 4, 2> K = P * H.transpose() * S_inv;
  if (probability < 1.0) {
    // PDAF (Bar-Shalom and Tse 1975) with one validated measurement of probability beta: the mean moves beta
    // of the way, and the covariance keeps (1 - beta) of the prediction plus the spread of the two
    // hypotheses.
    const double beta = probability;
    const Eigen::Matrix<double, 4, 1> Kv = K * u.innovation;
    x_ = x + beta * Kv;
    P_ = P - beta * (K * S * K.transpose()) + beta * (1.0 - beta) * (Kv * Kv.transpose());
    P_ = 0.5 * (P_ + P_.transpose());
  } else {
    x_ = x + K * u.innovation;
    // Joseph form keeps P symmetric positive definite.
    const Eigen::Matrix4d I_KH = Eigen::Matrix4d::Identity() - K * H;
    P_ = I_KH * P * I_KH.transpose() + K * R * K.transpose();
  }
  last_ = t;
  ++sightings_;
  u.accepted = true;
  return u;
}

bool GnssBiasEstimator::restartFromRefused() {
  const std::size_t need = static_cast<std::size_t>(options_.restart_sightings);
  if (refused_recent_.size() < need) return false;
  // The newest `need` refused sightings, each against the first of them: the drift may move the bias between
  // the two (its variance growth over dt), and both are noisy.
  const std::vector<Refused> group(refused_recent_.end() - static_cast<std::ptrdiff_t>(need),
                                   refused_recent_.end());
  const Refused& first = group.front();
  for (const Refused& r : group) {
    const Eigen::Matrix2d S =
        first.R + r.R + Eigen::Matrix2d::Identity() * options_.driftRate() * std::max(0.0, r.t - first.t);
    if (!(S.determinant() > 0.0)) return false;
    const Eigen::Vector2d d = r.y - first.y;
    if (std::sqrt(d.dot(S.inverse() * d)) > options_.gate_sigmas) return false;
  }
  // Replayed into a fresh estimate from the prior with restarts off: sightings the prior itself refuses (a
  // bias no unit of this model has) leave the old estimate as it was.
  refused_recent_.clear();
  GnssBiasOptions replay_options = options_;
  replay_options.restart_sightings = 0;
  GnssBiasEstimator replay(replay_options);
  for (const Refused& r : group) replay.update(r.t, r.y, r.R);
  if (replay.sightings() < need) return false;  // not every one of them fits one bias from the prior
  x_ = replay.x_;
  P_ = replay.P_;
  last_ = replay.last_;
  sightings_ += replay.sightings();
  ++restarts_;
  return true;
}

}  // namespace sensors
}  // namespace picker_localisation
