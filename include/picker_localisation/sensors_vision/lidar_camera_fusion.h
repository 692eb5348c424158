// LiDAR-camera fusion (Antonucci 2022, Sec. 3.4.2 and Algorithm 4): each camera box spans a bearing cone in the LiDAR
// plane; the nearest cluster inside the cone is labelled a person. A cluster track matched by a cone for
// `promote_after` frames is promoted (Algorithm 4's pm > m_p) and keeps that status while LiDAR alone tracks
// it; after `demote_after` consecutive camera frames that do not match it (fm > m_r) it is demoted.
// Several people are handled (one Init/Track state per track id). ROS-free.
#pragma once

#include <Eigen/Core>

#include <map>
#include <vector>

namespace picker_localisation {
namespace vision {

// A camera bearing cone, in the frame of the candidates (x forward, y left; angles positive to the left).
struct BearingCone {
  double bearing = 0.0;       // centre, rad
  double half_width = 0.0;    // half the angular width of the box, rad
  double confidence = 0.0;
};

struct FusionCandidate {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // m, in the camera's horizontal frame (x fwd, y left)
  int track_id = -1;                                    // cluster tracker id (-1: untracked)
  double confidence = 0.0;                              // LiDAR confidence
};

struct FusedPerson {
  int candidate = -1;           // index into the candidates
  int track_id = -1;
  bool camera_confirmed = false;  // matched by a cone in this frame or promoted earlier
  double confidence = 0.0;        // camera-confirmed people are weighted higher
};

struct LidarCameraFusionOptions {
  double cone_margin = 0.05;      // widens each cone on both sides, rad
  double max_range = 12.0;        // candidates farther than this are not matched to a cone, m
  int promote_after = 2;          // m_p: cone matches before a track is promoted
  int demote_after = 5;           // m_r: camera frames without a match before a promoted track is demoted
  double camera_weight = 2.0;     // confidence of a camera-confirmed person = min(1, weight * lidar conf) ...
  double camera_floor = 0.6;      // ... and at least this
};

class LidarCameraFusion {
 public:
  explicit LidarCameraFusion(LidarCameraFusionOptions options = {});

  // Index of the nearest candidate inside the (widened) cone, or -1.
  int nearestInCone(const BearingCone& cone, const std::vector<FusionCandidate>& candidates) const;

  // One fusion step. `camera_frame` is false when no camera frame arrived with these candidates (LiDAR only:
  // counters are not touched). Returns one FusedPerson per candidate, plus cone matches promoted to people.
  std::vector<FusedPerson> fuse(const std::vector<FusionCandidate>& candidates,
                                const std::vector<BearingCone>& cones, bool camera_frame);
  bool promoted(int track_id) const;
  void reset() { state_.clear(); }

 private:
  struct TrackState {
    int matches = 0;     // pm
    int mismatches = 0;  // fm
    bool promoted = false;
  };
  LidarCameraFusionOptions options_;
  std::map<int, TrackState> state_;
};

}  // namespace vision
}  // namespace picker_localisation
