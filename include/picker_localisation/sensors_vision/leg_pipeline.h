// The LiDAR people pipeline of one robot, as the leg_detector node runs it and as the offline runner
// (`experiment`) runs it: scan -> clusters (Antonucci 2022, Alg. 3) -> leg classifier -> people -> one cluster
// tracker PER SENSOR FRAME (Alg. 1 hysteresis; a laser that cannot see a person must not count a miss of the
// other laser's track) -> optional camera fusion (Alg. 4) -> people -> non-identifying Observations.
// ROS-free: the caller resolves the sensor pose (tf in the node, the simulated mount in the runner) and the
// camera cones.
//
// Options are the `leg_detector:` keys of config/vision.yaml (flat, the node's private parameters); the node
// and the runner both load them through LegPipelineOptions::fromYaml.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/sensors_vision/cluster_tracker.h"
#include "picker_localisation/sensors_vision/leg_detector.h"
#include "picker_localisation/sensors_vision/lidar_camera_fusion.h"

namespace picker_localisation {
namespace vision {

struct LegPipelineOptions {
  LegDetectorOptions detector;
  ClusterTrackerOptions tracker;
  LidarCameraFusionOptions fusion;
  double position_sigma = 0.3;    // m, std of a person's position (observation covariance)
  bool require_confirmed = true;  // only people on confirmed tracks (or camera-confirmed) are output
  bool camera_fusion = false;  // unclassified clusters become fusion candidates (node: detections_topic set)
  double max_fusion_cluster_width =
      0.8;                       // m, unclassified clusters up to this width may be promoted by a cone
  double cone_half_width = 0.1;  // rad, half width of a cone when the box edges are unknown
  // Negative information (LegPipeline::negativeObservation): a laser that sees through the place of a map
  // node and finds nobody there says the picker is not at that node, with the probability that it would have
  // detected a person standing there.
  bool negative_information = true;
  double negative_period = 2.0;      // s, at most one negative observation per laser frame per period
  double negative_p_detect = 0.5;    // detection probability in clear view up to negative_range_full
  double negative_range_full = 3.0;  // m from the laser: p_detect up to here, falling linearly to 0 at
  double negative_range_max = 5.0;   // m
  double negative_clearance = 1.5;   // m, nodes this close to a person candidate or live track get none

  // Reads the pipeline's keys of config/vision.yaml's `leg_detector:` section (missing keys keep the
  // defaults; the node's own keys: LegDetectorNodeOptions). `unknown`, when given, receives one message per
  // key that is not the pipeline's (naming the closest known key). Throws std::runtime_error naming the key
  // on a bad value (type or range, see validate()).
  static LegPipelineOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  // Applies the `leg_detector:` section of each file in order over `base` (later files win).
  static LegPipelineOptions fromYamlFiles(const std::vector<std::string>& files,
                                          std::vector<std::string>* unknown = nullptr);
  // The `leg_detector:` sections of the files merged key by key, later files winning.
  static YAML::Node mergedSections(const std::vector<std::string>& files);
  static const std::vector<std::string>& yamlKeys();
  // Empty when valid, else the first problem: "<key> = <value>: must be ...".
  std::string validate() const;
};

// A candidate person of one scan or cloud, in the fixed frame.
struct PersonCandidate {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double confidence = 0.0;
  std::string sensor = "lidar";
  bool classified = true;  // false: a person-sized cluster not classified as a person; output only when a
                           // camera cone selects it (Algorithm 4 promotes the nearest cluster in the cone)
};

// The camera frame to fuse with: cones in the camera's horizontal frame and that frame's pose.
struct CameraCones {
  Eigen::Isometry3d camera_from_fixed = Eigen::Isometry3d::Identity();
  std::vector<BearingCone> cones;
};

// A person the pipeline outputs (fixed frame).
struct TrackedPerson {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double variance = 0.09;        // m^2 per axis (camera-confirmed: half)
  std::string sensor = "lidar";  // lidar, lidar3d, lidar_camera, lidar3d_camera
  double confidence = 0.0;
  int track_id = -1;
  bool camera_confirmed = false;
  // m/s: the track's displacement over the tracker's velocity_window (ClusterTrack::window_velocity); none
  // until the track spans half the window, or with velocity_window 0.
  std::optional<Eigen::Vector2d> velocity;
};

class LegPipeline {
 public:
  LegPipeline(std::shared_ptr<const LegClassifier> classifier, LegPipelineOptions options);
  const LegPipelineOptions& options() const { return options_; }

  // Candidates of one laser scan: people of the leg detector and, with camera_fusion, every other cluster of
  // person size; `fixed_from_sensor` maps the scan frame into the fixed frame.
  std::vector<PersonCandidate> scanCandidates(const core::LaserScan& scan,
                                              const Eigen::Isometry3d& fixed_from_sensor) const;
  // Tracks (in `source_frame`'s own tracker), fuses and filters one scan's / cloud's candidates.
  std::vector<TrackedPerson> track(const std::string& source_frame, double stamp,
                                   const std::vector<PersonCandidate>& candidates,
                                   const CameraCones* camera = nullptr);
  std::vector<TrackedPerson> processScan(const std::string& source_frame, double stamp,
                                         const core::LaserScan& scan,
                                         const Eigen::Isometry3d& fixed_from_sensor,
                                         const CameraCones* camera = nullptr) {
    return track(source_frame, stamp, scanCandidates(scan, fixed_from_sensor), camera);
  }
  // Negative information of one scan (a robot that looks where the belief is and sees
  // nobody must move the belief): an anonymous Observation listing EVERY map node, with
  //   L(n) = 1 - p_d(r_n)   at nodes whose cell the laser sees through (the beams towards every point of the
  //                          half-edges to its neighbours, and 0.5 m to either side, reach 0.3 m past them:
  //                          nothing stands in the cell, a person the classifier missed included), with no
  //                          person candidate of this scan and no live track of this frame within
  //                          negative_clearance,
  //   L(n) = 1              everywhere else (out of view, occluded, or someone is there),
  // p_d(r) = negative_p_detect up to negative_range_full from the laser, linearly down to 0 at
  // negative_range_max. Issued at most once per negative_period per frame (successive scans of one place are
  // not independent looks); none when disabled, the period has not elapsed or no node qualifies. The same
  // observation concerns every picker: it only says "no person here".
  std::optional<core::Observation> negativeObservation(const std::string& source_frame, double stamp,
                                                       const core::LaserScan& scan,
                                                       const Eigen::Isometry3d& fixed_from_sensor,
                                                       const std::vector<PersonCandidate>& candidates,
                                                       const topology::TopologicalMap& map,
                                                       const std::string& robot_id);

  // The non-identifying Observation of one output person (sensor "lidar": the TPF picks its gamma by kind; a
  // camera-confirmed cluster is still a LiDAR position, with a tighter covariance), with the track's velocity
  // when it has one (the TPF's Eq. 8 velocity term, gamma_v of the sensor).
  static core::Observation observation(const TrackedPerson& person, const topology::TopologicalMap& map,
                                       double stamp, const std::string& robot_id);

  std::size_t liveTracks() const;
  // Forgets every track and the camera promotion state (the clock jumped back).
  void reset() {
    trackers_.clear();
    fusion_.reset();
    last_negative_.clear();
  }

 private:
  LegPipelineOptions options_;
  LegDetector detector_;
  std::map<std::string, ClusterTracker> trackers_;
  std::map<std::string, double> last_negative_;  // frame -> stamp of its last negative observation
  LidarCameraFusion fusion_;
};

}  // namespace vision
}  // namespace picker_localisation
