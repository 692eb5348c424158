// Cluster tracking across scans: Antonucci 2022 Algorithm 1 (hit/miss hysteresis: a track is confirmed after T_a
// updates and removed after T_o scans without one) with the Munkres assignment of Sec. 6.3.3 in place of
// Algorithm 1's first-match loop, and a distance gate d_min. Positions are in one fixed frame (the node
// transforms to map/odom first, which is Algorithm 4's RotoTranslate step). ROS-free, deterministic.
#pragma once

#include <Eigen/Core>

#include <deque>
#include <utility>
#include <vector>

namespace picker_localisation {
namespace vision {

struct ClusterTrackerOptions {
  double gate_distance = 0.5;   // d_min: a detection farther than this from a track is never assigned to it, m
  int hits_to_confirm = 3;      // T_a: consecutive updates before a tentative track is confirmed
  int misses_to_delete = 5;     // T_o: scans without an update before a track is removed
  int tentative_misses = 1;     // a tentative track missing this many scans is dropped at once
  double velocity_smoothing = 0.5;  // weight of the newest finite-difference velocity (0..1]
  // Not in Antonucci 2022: the track's displacement over about this many seconds (window_velocity), the
  // walking velocity of a person whose legs swing; 0: none. A scan-to-scan difference of a leg pair's
  // centroid is mostly the legs' swing (several m/s at 10 Hz).
  double velocity_window = 2.0;  // s
  int first_id = 0;             // ids are first_id, first_id + 1, ... (several trackers can keep ids disjoint)
};

struct ClusterTrack {
  int id = -1;                       // stable id, unique for the tracker's life
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity = Eigen::Vector2d::Zero();  // m/s, smoothed finite difference
  // m/s, (newest - oldest position) / their stamps' span over the last velocity_window; set only once the
  // span covers half the window (has_window_velocity).
  Eigen::Vector2d window_velocity = Eigen::Vector2d::Zero();
  bool has_window_velocity = false;
  std::deque<std::pair<double, Eigen::Vector2d>> recent;  // (stamp, position) of the updates in the window
  int hits = 0;                      // updates so far
  int misses = 0;                    // consecutive scans without an update
  bool confirmed = false;            // track_j of Algorithm 1
  bool updated = false;              // updated_j in the last step
  int detection = -1;                // index of the detection assigned in the last step, -1 if none
  double last_update = 0.0;          // stamp of the last update, s
};

class ClusterTracker {
 public:
  explicit ClusterTracker(ClusterTrackerOptions options = {});
  const ClusterTrackerOptions& options() const { return options_; }

  // One step with the detections of one scan at `stamp`. Stamps going backwards reset nothing but are not
  // used for velocity. Returns every live track (confirmed or not) after the step.
  const std::vector<ClusterTrack>& update(double stamp, const std::vector<Eigen::Vector2d>& detections);
  const std::vector<ClusterTrack>& tracks() const { return tracks_; }
  std::vector<ClusterTrack> confirmedTracks() const;
  void reset();

 private:
  // Appends the track's new position to its window and updates window_velocity.
  void remember(ClusterTrack& t, double stamp) const;

  ClusterTrackerOptions options_;
  std::vector<ClusterTrack> tracks_;
  int next_id_ = 0;
  double last_stamp_ = 0.0;
  bool has_stamp_ = false;
};

}  // namespace vision
}  // namespace picker_localisation
