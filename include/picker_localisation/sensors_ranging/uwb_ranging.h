// UWB ranges from anchors on a robot to the picker's tags -> per tag a Range Histogram Filter (Sarmento et al.
// 2024) -> identifying Observation; or, as an alternative input, the two-antenna range + phase-difference
// relative position (Periotto and Sartori). ROS-free: the uwb_ranging node resolves anchor / camera mounts and
// the robot pose from tf and feeds this class; the offline experiment runner feeds it directly.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/core/sensor_data.h"
#include "picker_localisation/sensors_ranging/range_histogram_filter.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace sensors {

// Periotto and Sartori (after the PDoA patent it cites): relative position of a tag from the range r to antenna 1 and
// the path difference p = r - r2 to antenna 2, antennas d apart on the x axis (antenna 1 at the origin):
//   x = (d^2 + 2 r p - p^2) / (2 d),  y = +sqrt(r^2 - x^2) (the sign of y is ambiguous; `positive_y` picks it).
// nullopt when d <= 0, r < 0, |p| > d (no geometry) or any input is not finite. r^2 < x^2 (noise) gives y = 0.
std::optional<Eigen::Vector2d> relativePositionFromPathDifference(double r, double p, double d,
                                                                  bool positive_y = true);
// Path difference from a phase difference (rad) at carrier wavelength lambda (m): p = dphi * lambda / (2 pi).
double pathDifferenceFromPhase(double phase_difference, double wavelength);
// Range + angle of arrival (UwbRange.pdoa_angle: rad in the anchor frame, positive to the left) ->
// position in the anchor frame and its covariance: radial variance sigma_r^2, tangential (r sigma_a)^2.
Eigen::Vector2d relativePositionFromAngle(double r, double angle);
Eigen::Matrix2d relativePositionCovariance(double r, double angle, double range_variance, double angle_sigma);

// One range (core::UwbRange) with its anchor's mount on the robot (tf, or the simulator).
struct UwbRangeInput : core::UwbRange {
  Eigen::Isometry2d anchor_in_robot = Eigen::Isometry2d::Identity();  // anchor mount in base_link
};

// Camera detections of one image (non-identifying bearings), robot frame.
struct CameraBearings {
  double stamp = 0.0;
  std::vector<BearingMeasurement> bearings;  // origin + direction in base_link
};

enum class UwbRejection { kNone = 0, kUnknownTag, kNotFinite, kNegativeRange, kOutOfRange, kOutOfOrder };
const char* toString(UwbRejection r);

struct UwbRangingOptions {
  std::string sensor = "uwb";
  RhfOptions rhf;
  // m, longer ranges are rejected (Sarmento et al. 2024, Sec. 5.1 uses 12 m). Keep it below the grid's half
  // size minus the anchor offsets: a person beyond the grid edge cannot be represented (the default suits the
  // 20 m grid).
  double max_range = 9.5;
  double batch_window = 0.1;      // s, ranges of one tag within this window form one RHF update
  double bearing_max_age = 0.2;   // s, camera bearings older than this (vs the batch stamp) are not used
  // pdoa_mode: "ignore" (RHF on ranges only), "bearing" (a PDoA angle becomes a bearing in the RHF), or
  // "direct" (Periotto and Sartori relative position -> observation, bypassing the RHF for that range).
  std::string pdoa_mode = "bearing";
  double pdoa_angle_sigma = 0.17; // rad (~10 deg)
  double min_sigma = 0.3;         // m, floor of the node likelihood's sigma
  double cutoff_sigmas = 3.0;
  double reset_after = 5.0;       // s without ranges of a tag -> its filter restarts from the uniform prior
  // An RHF estimate becomes an observation only when it is unimodal enough to be a Gaussian: its largest
  // standard deviation <= max_output_sigma (one anchor's ring or two anchors' mirror pair are not) and no
  // support cell lies on the grid edge. Suppressed estimates still update the filter (counted).
  double max_output_sigma = 2.0;  // m

  // The keys of config/uwb_ranging.yaml (RHF keys: grid_size_x, grid_size_y, grid_resolution, max_speed,
  // p_threshold, p_min_uwb, p_min_cam, p_min_obs, p_min_inov, default_range_sigma, bearing_sigma,
  // output_threshold, camera_gate; node-only keys accepted and ignored). A bad value throws std::runtime_error
  // "uwb_ranging: <key> = <value>: must be ..."; an unknown key goes to *unknown with the closest known one.
  static UwbRangingOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static UwbRangingOptions fromYamlFile(const std::string& path, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();
  std::string validate() const;  // "" or "<key> = <value>: must be ..."
};

struct UwbCounters {
  std::size_t received = 0, accepted = 0, unknown_tag = 0, not_finite = 0, negative_range = 0, out_of_range = 0,
              out_of_order = 0, updates = 0, observations = 0, bearings = 0, suppressed = 0;
};

class UwbRanging {
 public:
  UwbRanging(core::PickerRegistry registry, std::shared_ptr<const topology::TopologicalMap> map,
             UwbRangingOptions options = {});

  // Adds one range. `robot_pose`: base_link in the map frame at the range's stamp (x, y, yaw as Isometry2d).
  // Closes and processes the tag's previous batch when this range falls outside its window (or repeats an
  // anchor): the resulting observations are appended to *out. Returns the rejection (kNone when accepted).
  UwbRejection addRange(const UwbRangeInput& input, const Eigen::Isometry2d& robot_pose,
                        std::vector<core::Observation>* out, std::string* reason = nullptr);
  // Camera bearings for the next updates (kept until bearing_max_age has passed).
  void addBearings(const CameraBearings& bearings);
  // Processes every batch whose window ended before `now` (s), and frees the filters of tags not ranged for
  // reset_after s. Call periodically.
  void flush(double now, std::vector<core::Observation>* out);

  const UwbCounters& counters() const { return counters_; }
  // Forgets every tag's batch and filter (after the clock jumped back); counters stay.
  void reset() {
    tags_.clear();
    newest_stamp_ = -1e300;
  }
  // The pickers changed at run time (tpf_tracker's list): a tag no longer worn by the same picker loses its
  // filter (it would carry the old wearer's position).
  void setRegistry(core::PickerRegistry registry);
  // The map edited at run time: observations are built on `map` from the next one (the tags' filters are
  // metric, in the map frame, and are kept).
  void setMap(std::shared_ptr<const topology::TopologicalMap> map) {
    if (map) map_ = std::move(map);
  }
  const RangeHistogramFilter* filter(const std::string& tag_id) const;  // nullptr before the tag's first update
  const UwbRangingOptions& options() const { return options_; }

 private:
  struct Batch {
    double first_stamp = 0.0, last_stamp = 0.0;
    std::string robot_id;
    Eigen::Isometry2d robot_pose = Eigen::Isometry2d::Identity();  // at last_stamp
    std::vector<std::string> anchors;
    std::vector<RangeMeasurement> ranges;
    std::vector<BearingMeasurement> pdoa_bearings;
  };
  struct TagState {
    std::string picker_id;
    RangeHistogramFilter filter;
    double last_stamp = -1e300;                         // newest accepted range
    std::optional<Batch> batch;
    explicit TagState(const RhfOptions& o) : filter(o) {}
  };
  void processBatch(const std::string& tag, TagState& state, std::vector<core::Observation>* out);
  core::Observation makeObservation(const std::string& picker_id, const std::string& robot_id, double stamp,
                                    const Eigen::Vector2d& p_map, const Eigen::Matrix2d& c_map) const;

  core::PickerRegistry registry_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  UwbRangingOptions options_;
  std::map<std::string, TagState> tags_;  // tags ranged within reset_after of the newest range (flush evicts)
  double newest_stamp_ = -1e300;           // newest accepted range, s
  std::vector<CameraBearings> bearings_;
  UwbCounters counters_;
};

}  // namespace sensors
}  // namespace picker_localisation
