#include "picker_localisation/sensors_vision/cluster_tracker.h"

#include <algorithm>
#include <cmath>

#include "picker_localisation/sensors_vision/munkres.h"

namespace picker_localisation {
namespace vision {

ClusterTracker::ClusterTracker(ClusterTrackerOptions options) : options_(options), next_id_(options.first_id) {}

void ClusterTracker::reset() {
  tracks_.clear();
  has_stamp_ = false;
}

void ClusterTracker::remember(ClusterTrack& t, double stamp) const {
  const double window = options_.velocity_window;
  if (!(window > 0.0) || !std::isfinite(stamp)) return;
  if (!t.recent.empty() && !(stamp > t.recent.back().first)) t.recent.clear();  // a stamp back: start again
  t.recent.emplace_back(stamp, t.position);
  // Drop the oldest while the next one is at least `window` old: the oldest kept is then at least `window`
  // old (the span covers the window once the track is that old).
  while (t.recent.size() > 2 && stamp - t.recent[1].first >= window) t.recent.pop_front();
  const double span = stamp - t.recent.front().first;
  t.has_window_velocity = span >= 0.5 * window;
  t.window_velocity = t.has_window_velocity ? Eigen::Vector2d((t.position - t.recent.front().second) / span)
                                            : Eigen::Vector2d::Zero();
}

const std::vector<ClusterTrack>& ClusterTracker::update(double stamp, const std::vector<Eigen::Vector2d>& detections) {
  const double dt = has_stamp_ ? stamp - last_stamp_ : 0.0;
  const int n = static_cast<int>(tracks_.size()), m = static_cast<int>(detections.size());
  // Cost = distance; pairs outside the gate get a cost larger than any gated pair so that Munkres only uses
  // them when forced, and such pairs are then rejected (gating after assignment).
  const double big = options_.gate_distance * 10.0 + 1.0;
  Eigen::MatrixXd cost(n, m);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double d = (tracks_[i].position - detections[j]).norm();
      cost(i, j) = d < options_.gate_distance ? d : big;
    }
  const std::vector<int> assign = solveAssignment(cost);
  std::vector<char> detection_used(m, 0);
  for (int i = 0; i < n; ++i) {
    auto& t = tracks_[i];
    const int j = assign[i];
    if (j >= 0 && cost(i, j) < options_.gate_distance) {
      detection_used[j] = 1;
      if (dt > 0.0 && t.hits > 0) {
        const Eigen::Vector2d v = (detections[j] - t.position) / dt;
        // The first finite difference initialises the velocity; later ones are smoothed exponentially.
        t.velocity = t.hits == 1 ? v
                                 : Eigen::Vector2d(options_.velocity_smoothing * v +
                                                   (1.0 - options_.velocity_smoothing) * t.velocity);
      }
      t.position = detections[j];
      remember(t, stamp);
      t.updated = true;
      t.detection = j;
      ++t.hits;
      t.misses = 0;
      t.last_update = stamp;
      // Algorithm 1 lines 30-32: a tentative track becomes a track after T_a updates.
      if (!t.confirmed && t.hits >= options_.hits_to_confirm) t.confirmed = true;
    } else {
      t.updated = false;
      t.detection = -1;
      ++t.misses;
    }
  }
  // Algorithm 1 lines 16-28: remove tracks without correspondence for T_o scans (tentative ones sooner).
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const ClusterTrack& t) {
                                 return t.confirmed ? t.misses >= options_.misses_to_delete
                                                    : t.misses >= options_.tentative_misses;
                               }),
                tracks_.end());
  // Algorithm 1 lines 9-12: unmatched detections allocate new (tentative) clusters.
  for (int j = 0; j < m; ++j) {
    if (detection_used[j]) continue;
    ClusterTrack t;
    t.id = next_id_++;
    t.position = detections[j];
    t.hits = 1;
    t.updated = true;
    t.detection = j;
    t.last_update = stamp;
    t.confirmed = options_.hits_to_confirm <= 1;
    remember(t, stamp);
    tracks_.push_back(t);
  }
  if (!has_stamp_ || stamp >= last_stamp_) {
    last_stamp_ = stamp;
    has_stamp_ = true;
  }
  return tracks_;
}

std::vector<ClusterTrack> ClusterTracker::confirmedTracks() const {
  std::vector<ClusterTrack> out;
  for (const auto& t : tracks_)
    if (t.confirmed) out.push_back(t);
  return out;
}

}  // namespace vision
}  // namespace picker_localisation
