#include "picker_localisation/eval/ukf_metric_tracker.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

namespace picker_localisation {
namespace eval {

namespace {
constexpr int kN = 4;  // state size

struct SigmaPoints {
  std::array<Eigen::Vector4d, 2 * kN + 1> x;
  std::array<double, 2 * kN + 1> wm, wc;
};

SigmaPoints sigmaPoints(const Eigen::Vector4d& mean, const Eigen::Matrix4d& P, const UkfTrackerParams& p) {
  const double lambda = p.alpha * p.alpha * (kN + p.kappa) - kN;
  SigmaPoints s;
  Eigen::Matrix4d scaled = (kN + lambda) * P;
  scaled = 0.5 * (scaled + scaled.transpose()).eval();
  Eigen::LLT<Eigen::Matrix4d> llt(scaled);
  Eigen::Matrix4d L = llt.matrixL();
  if (llt.info() != Eigen::Success) {  // regularise a covariance that lost definiteness to rounding
    L = Eigen::LLT<Eigen::Matrix4d>(scaled + 1e-9 * Eigen::Matrix4d::Identity()).matrixL();
  }
  s.x[0] = mean;
  s.wm[0] = lambda / (kN + lambda);
  s.wc[0] = s.wm[0] + (1.0 - p.alpha * p.alpha + p.beta);
  for (int i = 0; i < kN; ++i) {
    s.x[1 + i] = mean + L.col(i);
    s.x[1 + kN + i] = mean - L.col(i);
    s.wm[1 + i] = s.wm[1 + kN + i] = 0.5 / (kN + lambda);
    s.wc[1 + i] = s.wc[1 + kN + i] = s.wm[1 + i];
  }
  return s;
}

// Measurement prediction: mean, innovation covariance S and cross covariance Pxz.
std::tuple<Eigen::Vector2d, Eigen::Matrix2d, Eigen::Matrix<double, 4, 2>> predictMeasurement(
    const MetricTrack& t, const Eigen::Matrix2d& R, const UkfTrackerParams& p) {
  const SigmaPoints s = sigmaPoints(t.x, t.P, p);
  Eigen::Vector2d zm = Eigen::Vector2d::Zero();
  for (int i = 0; i < 2 * kN + 1; ++i) zm += s.wm[i] * s.x[i].head<2>();  // h(x) = position
  Eigen::Matrix2d S = R;
  Eigen::Matrix<double, 4, 2> Pxz = Eigen::Matrix<double, 4, 2>::Zero();
  for (int i = 0; i < 2 * kN + 1; ++i) {
    const Eigen::Vector2d dz = s.x[i].head<2>() - zm;
    S += s.wc[i] * dz * dz.transpose();
    Pxz += s.wc[i] * (s.x[i] - t.x) * dz.transpose();
  }
  return {zm, S, Pxz};
}
}  // namespace

UkfMetricTracker::UkfMetricTracker(UkfTrackerParams params) : params_(params) {}

void UkfMetricTracker::predictTrack(MetricTrack& t, double dt) const {
  if (dt <= 0.0) return;
  const SigmaPoints s = sigmaPoints(t.x, t.P, params_);
  std::array<Eigen::Vector4d, 2 * kN + 1> fx;
  Eigen::Vector4d mean = Eigen::Vector4d::Zero();
  for (int i = 0; i < 2 * kN + 1; ++i) {  // f(x): constant velocity
    fx[i] = s.x[i];
    fx[i].head<2>() += dt * s.x[i].tail<2>();
    mean += s.wm[i] * fx[i];
  }
  // Q of the continuous white-acceleration model, per axis [dt^3/3 dt^2/2; dt^2/2 dt] * q.
  const double q = params_.acceleration_noise;
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  for (int a = 0; a < 2; ++a) {
    P(a, a) = q * dt * dt * dt / 3.0;
    P(a, a + 2) = P(a + 2, a) = q * dt * dt / 2.0;
    P(a + 2, a + 2) = q * dt;
  }
  for (int i = 0; i < 2 * kN + 1; ++i) {
    const Eigen::Vector4d d = fx[i] - mean;
    P += s.wc[i] * d * d.transpose();
  }
  t.x = mean;
  t.P = 0.5 * (P + P.transpose());
}

double UkfMetricTracker::mahalanobis2(const MetricTrack& t, const Eigen::Vector2d& z,
                                      const Eigen::Matrix2d& R) const {
  const auto [zm, S, Pxz] = predictMeasurement(t, R, params_);
  (void)Pxz;
  const Eigen::Vector2d nu = z - zm;
  return nu.dot(S.ldlt().solve(nu));
}

void UkfMetricTracker::updateTrack(MetricTrack& t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) const {
  const auto [zm, S, Pxz] = predictMeasurement(t, R, params_);
  const Eigen::Matrix<double, 4, 2> K = Pxz * S.inverse();
  t.x += K * (z - zm);
  t.P -= K * S * K.transpose();
  t.P = 0.5 * (t.P + t.P.transpose());
  const double speed = t.x.tail<2>().norm();
  if (speed > params_.max_speed) t.x.tail<2>() *= params_.max_speed / speed;
  ++t.updates;
}

MetricTrack& UkfMetricTracker::newTrack(const Eigen::Vector2d& z, const Eigen::Matrix2d& R,
                                        const std::string& picker_id) {
  MetricTrack t;
  t.uuid = next_uuid_++;
  t.picker_id = picker_id;
  t.x << z.x(), z.y(), 0.0, 0.0;
  t.P.setZero();
  t.P.topLeftCorner<2, 2>() = R;
  const double v2 = params_.init_velocity_sigma * params_.init_velocity_sigma;
  t.P(2, 2) = t.P(3, 3) = v2;
  t.stamp = stamp_;
  t.updates = 1;
  tracks_.push_back(t);
  return tracks_.back();
}

bool UkfMetricTracker::predictTo(double stamp) {
  if (!std::isfinite(stamp) || stamp < stamp_) return false;
  for (auto& t : tracks_) {
    predictTrack(t, stamp - t.stamp);
    t.stamp = stamp;
  }
  stamp_ = stamp;
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const MetricTrack& t) {
                                 return 0.5 * (t.P(0, 0) + t.P(1, 1)) > params_.max_position_variance;
                               }),
                tracks_.end());
  return true;
}

void UkfMetricTracker::rememberEstimates() {
  for (const auto& t : tracks_) {
    if (!t.picker_id.empty()) last_estimate_[t.picker_id] = t.x.head<2>();
  }
}

bool UkfMetricTracker::addGnss(double stamp, const std::string& picker_id, const Eigen::Vector2d& position,
                               const Eigen::Matrix2d& covariance) {
  if (picker_id.empty() || !position.allFinite() || !covariance.allFinite()) return false;
  if (!predictTo(stamp)) return false;
  auto own = std::find_if(tracks_.begin(), tracks_.end(),
                          [&](const MetricTrack& t) { return t.picker_id == picker_id; });
  if (own != tracks_.end()) {
    updateTrack(*own, position, covariance);  // identified: no gate
  } else {
    MetricTrack* best = nullptr;
    double best_d2 = params_.gate_chi2;
    for (auto& t : tracks_) {
      if (!t.picker_id.empty()) continue;
      const double d2 = mahalanobis2(t, position, covariance);
      if (d2 < best_d2) {
        best_d2 = d2;
        best = &t;
      }
    }
    if (best) {
      best->picker_id = picker_id;
      updateTrack(*best, position, covariance);
    } else {
      newTrack(position, covariance, picker_id);
    }
  }
  rememberEstimates();
  return true;
}

std::size_t UkfMetricTracker::addDetections(double stamp, const std::vector<Eigen::Vector2d>& positions) {
  if (!predictTo(stamp)) return 0;
  const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * params_.lidar_sigma * params_.lidar_sigma;
  // Global nearest neighbour: every gated (track, detection) pair, cheapest first, each used once.
  struct Pair {
    double d2;
    std::size_t track, det;
  };
  std::vector<Pair> pairs;
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    for (std::size_t j = 0; j < positions.size(); ++j) {
      if (!positions[j].allFinite()) continue;
      const double d2 = mahalanobis2(tracks_[i], positions[j], R);
      if (d2 < params_.gate_chi2) pairs.push_back({d2, i, j});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
    return a.d2 != b.d2 ? a.d2 < b.d2 : (a.track != b.track ? a.track < b.track : a.det < b.det);
  });
  std::vector<bool> track_used(tracks_.size(), false), det_used(positions.size(), false);
  std::size_t associated = 0;
  for (const auto& p : pairs) {
    if (track_used[p.track] || det_used[p.det]) continue;
    track_used[p.track] = det_used[p.det] = true;
    updateTrack(tracks_[p.track], positions[p.det], R);
    ++associated;
  }
  for (std::size_t j = 0; j < positions.size(); ++j) {
    if (!det_used[j] && positions[j].allFinite()) newTrack(positions[j], R, "");
  }
  rememberEstimates();
  return associated;
}

std::optional<Eigen::Vector2d> UkfMetricTracker::estimate(const std::string& picker_id) const {
  for (const auto& t : tracks_) {
    if (t.picker_id == picker_id) return Eigen::Vector2d(t.x.head<2>());
  }
  auto it = last_estimate_.find(picker_id);
  if (it == last_estimate_.end()) return std::nullopt;
  return it->second;
}

}  // namespace eval
}  // namespace picker_localisation
