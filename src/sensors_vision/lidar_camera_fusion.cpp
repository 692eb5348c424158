#include "picker_localisation/sensors_vision/lidar_camera_fusion.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace picker_localisation {
namespace vision {
namespace {

double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

LidarCameraFusion::LidarCameraFusion(LidarCameraFusionOptions options) : options_(options) {}

int LidarCameraFusion::nearestInCone(const BearingCone& cone, const std::vector<FusionCandidate>& candidates) const {
  int best = -1;
  double best_range = options_.max_range;
  const double half = cone.half_width + options_.cone_margin;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const auto& p = candidates[i].position;
    const double range = p.norm();
    if (!(range > 1e-6) || p.x() <= 0.0) continue;  // behind the camera
    if (std::abs(wrapAngle(std::atan2(p.y(), p.x()) - cone.bearing)) > half) continue;
    if (range < best_range) {  // Sec. 3.4.2: the nearest cluster within the conical sector
      best_range = range;
      best = static_cast<int>(i);
    }
  }
  return best;
}

bool LidarCameraFusion::promoted(int track_id) const {
  const auto it = state_.find(track_id);
  return it != state_.end() && it->second.promoted;
}

std::vector<FusedPerson> LidarCameraFusion::fuse(const std::vector<FusionCandidate>& candidates,
                                                 const std::vector<BearingCone>& cones, bool camera_frame) {
  std::vector<char> matched(candidates.size(), 0);
  if (camera_frame)
    for (const auto& cone : cones) {
      const int i = nearestInCone(cone, candidates);
      if (i >= 0) matched[i] = 1;
    }
  std::vector<FusedPerson> out;
  std::set<int> seen_tracks;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const auto& c = candidates[i];
    FusedPerson p;
    p.candidate = static_cast<int>(i);
    p.track_id = c.track_id;
    bool confirmed = matched[i] != 0;
    if (c.track_id >= 0) {
      seen_tracks.insert(c.track_id);
      auto& s = state_[c.track_id];
      if (camera_frame) {
        if (matched[i]) {
          ++s.matches;  // Algorithm 4 line 7
          s.mismatches = 0;
          if (s.matches >= options_.promote_after) s.promoted = true;  // line 9-12
        } else if (s.promoted && ++s.mismatches >= options_.demote_after) {  // lines 16-22
          s = TrackState();
        }
      }
      confirmed = confirmed || s.promoted;
    }
    p.camera_confirmed = confirmed;
    p.confidence = confirmed ? std::max(options_.camera_floor, std::min(1.0, options_.camera_weight * c.confidence))
                             : c.confidence;
    out.push_back(p);
  }
  // Tracks that disappeared from the LiDAR lose their state (Algorithm 4: "the object itself is removed").
  for (auto it = state_.begin(); it != state_.end();)
    it = seen_tracks.count(it->first) ? std::next(it) : state_.erase(it);
  return out;
}

}  // namespace vision
}  // namespace picker_localisation
