// `ukf_metric` baseline of Table II ("Dondrup et al. [23]"): a metric multi-person tracker in the spirit of
// bayes_people_tracker, written here with Eigen. Each track is an Unscented Kalman Filter over
// x = [px, py, vx, vy] with a constant-velocity model (white-acceleration noise); LiDAR leg detections are
// anonymous position measurements associated by global nearest neighbour inside a Mahalanobis gate; GNSS
// fixes are identified position updates. The per-picker estimate is mapped to the nearest node by the caller.
//
// Picker <-> track association follows Navigate-and-Seek Sec. VI-C: a picker's fix updates the track already
// labelled with that picker; when the picker has no track (first fix, or its track was lost), the fix adopts
// the nearest unlabelled track inside the gate, else starts a new labelled track. Unassociated LiDAR
// detections start anonymous tracks (as bayes_people_tracker does); a track whose position variance exceeds
// `max_position_variance` is deleted. When a picker has no track, estimate() returns the last estimate it
// had. ROS-free, deterministic (no random draws).
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace picker_localisation {
namespace eval {

struct UkfTrackerParams {
  double acceleration_noise = 0.5;      // white-acceleration spectral density of the CV model, m^2/s^3
  double lidar_sigma = 0.15;            // std of a leg detection's position, m
  double init_velocity_sigma = 1.0;     // std of the velocity of a new track, m/s
  double gate_chi2 = 9.21;              // Mahalanobis gate (chi^2, 2 dof, 99 %)
  double max_position_variance = 16.0;  // a track is deleted when (P_xx + P_yy) / 2 exceeds this, m^2
  double max_speed = 2.5;               // velocity is clipped to this after each update, m/s
  // Unscented transform (Julier/Wan-van der Merwe): alpha, beta, kappa.
  double alpha = 1.0, beta = 2.0, kappa = 0.0;
};

struct MetricTrack {
  std::uint64_t uuid = 0;
  std::string picker_id;  // "" while anonymous
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P = Eigen::Matrix4d::Identity();
  double stamp = 0.0;  // time the state refers to, s
  std::size_t updates = 0;
};

class UkfMetricTracker {
 public:
  explicit UkfMetricTracker(UkfTrackerParams params = {});

  // Predicts every track to `stamp` (s) and deletes diverged tracks. A stamp before the current time is
  // ignored (returns false): measurements must come in time order.
  bool predictTo(double stamp);
  // Identified GNSS position (map frame, m) with its covariance (m^2). Returns false when rejected
  // (non-finite, out of order).
  bool addGnss(double stamp, const std::string& picker_id, const Eigen::Vector2d& position,
               const Eigen::Matrix2d& covariance);
  // Anonymous LiDAR detections (map frame, m) taken at one instant. Returns the number associated to tracks.
  std::size_t addDetections(double stamp, const std::vector<Eigen::Vector2d>& positions);

  // Current position of the picker's track, else the last one it had; nullopt before its first fix.
  std::optional<Eigen::Vector2d> estimate(const std::string& picker_id) const;
  const std::vector<MetricTrack>& tracks() const { return tracks_; }
  double stamp() const { return stamp_; }
  const UkfTrackerParams& params() const { return params_; }

  // One UKF step on a track (public for tests): predict by dt with the CV model, update with a position.
  void predictTrack(MetricTrack& t, double dt) const;
  void updateTrack(MetricTrack& t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) const;
  // Squared Mahalanobis distance of a position to the track's predicted measurement.
  double mahalanobis2(const MetricTrack& t, const Eigen::Vector2d& z, const Eigen::Matrix2d& R) const;

 private:
  MetricTrack& newTrack(const Eigen::Vector2d& z, const Eigen::Matrix2d& R, const std::string& picker_id);
  void rememberEstimates();

  UkfTrackerParams params_;
  std::vector<MetricTrack> tracks_;
  std::map<std::string, Eigen::Vector2d> last_estimate_;
  std::uint64_t next_uuid_ = 1;
  double stamp_ = -1e300;
};

}  // namespace eval
}  // namespace picker_localisation
