// RFID reads of picker tags by a robot's antenna -> identifying Observations (Navigate-and-Seek Sec. IV/VI:
// an RFID detection is an identifying observation with gamma_RFID = 1). ROS-free.
//
// Sensor model (read_model "logistic", the default): the probability that one read attempt of an antenna
// reads a tag at distance d is the logistic fall-off
//   p_read(d) = p_max / (1 + exp((d - d50) / width))  for d <= max_range, 0 beyond,
// the same family and (by default) the same parameters as the simulator (config/sim.yaml `rfid`,
// sim::rfidReadProbability). d is the 3D antenna-tag distance sqrt(d_xy^2 + height_difference^2), d_xy the
// planar distance from the antenna to the map node. Reading the curve as a likelihood over the picker's node:
//   positive (the tag was read): L(n) = p_read(d(n)), listed only for nodes with p_read(d(n)) >= min_relative *
//     p_max (the cut-off radius r_c = min(max_range, d50 + width ln(1/min_relative - 1)), about 7.2 m by default,
//     keeps the observation sparse; beyond it the likelihood is treated as 0);
//   negative (an antenna that is reading has not read the tag for a window): L(n) = 1 - p_detect * s(d(n))
//     with s = p_read / p_max in [0, 1] the normalised curve, i.e. p_detect is the probability of at least one
//     read within the window for a tag next to the antenna and it falls off with the same shape; L = 1
//     beyond r_c.
// (read_model "disc" keeps the former hard model: L = 1 inside |n - antenna| <= read_range, 1 - p_detect inside
// for negative information.) A directional antenna (beam_half_angle < pi) additionally restricts the region to
// |bearing(n) - yaw| <= beam_half_angle. When no node is inside the region, the node nearest to the antenna gets
// L = 1 (an observation is never empty).
// Negative information (configurable): while an antenna is reading (it has produced reads with gaps shorter than
// `negative_window` s for at least `negative_window` s), every picker with RFID tags that this antenna has not
// read within `negative_window` gets, at most once per `negative_period` s, an identifying Observation (sent with
// each read) with the negative likelihood above inside the region and L(n) = 1 for every other map node (all map
// nodes are listed, because unlisted nodes mean L = 0). Limitation: an antenna that reads no tag at all is not
// known to be reading (RfidReading has no "inventory round" event), so it gives no negative information.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/core/sensor_data.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace sensors {

// One read (core::RfidReading) with its antenna's pose resolved into the map frame (tf, or the simulator).
struct RfidRead : core::RfidReading {
  Eigen::Vector3d antenna_pose = Eigen::Vector3d::Zero();  // x, y (m), yaw (rad) in the map frame
};

enum class RfidRejection { kNone = 0, kUnknownTag, kNotFinite, kWeakSignal, kOutOfOrder };
const char* toString(RfidRejection r);

struct RfidModelOptions {
  std::string sensor = "rfid";
  std::string read_model = "logistic";  // "logistic" (p_read(d), see above) or "disc" (hard read_range disc)
  // logistic model; defaults equal the simulator's documented defaults (config/sim.yaml rfid)
  double p_max = 0.95;                // read probability per attempt next to the antenna
  double d50 = 4.0;                   // m, distance where p_read = p_max / 2
  double width = 0.7;                 // m, steepness of the fall-off
  double max_range = 8.0;             // m, p_read = 0 beyond
  double height_difference = 0.0;     // m, antenna height minus tag height (sim: both 1.0 m)
  double min_relative = 0.01;         // nodes with p_read < min_relative * p_max are not listed (sparsity cut-off)
  // disc model
  double read_range = 3.0;            // m, radius of the read region around the antenna
  double beam_half_angle = 3.14159265358979323846;  // rad, half opening of the read region (pi: omnidirectional)
  double min_rssi = -1e9;             // dBm, weaker reads are rejected as unreliable (default: accept all)
  bool negative_information = true;
  double negative_window = 5.0;       // s
  double negative_period = 5.0;       // s, at most one negative observation per picker and antenna per period
  double p_detect = 0.7;              // probability that a tag inside the read region is read within the window
  double out_of_order_tolerance = 0.0;  // s, reads older than the antenna's newest read by more are rejected
  // Read attempts per second of one antenna for one tag (the reader's inventory rate; the simulator's
  // rfid.rate). > 0: a read that follows the same antenna's previous read of the same picker after a gap
  // also counts the m = round(gap * attempt_rate) - 1 failed attempts in between, the first read of a tag
  // (an infinite gap) max_failed_attempts: L(n) = p_read(d) (1 - p_read(d))^m, so a tag read now and then,
  // or read for the first time as the robot comes into range, is placed away from the antenna instead of next
  // to it (successful reads alone pull the belief towards the robot). 0: L(n) = p_read(d).
  double attempt_rate = 2.0;
  int max_failed_attempts = 10;  // cap on m: the likelihood is taken at the antenna's pose of the read, and
                                 // the robot moves during a long gap (1 m/s: 5 m in the 10 attempts of 5 s)

  // The model's keys of config/rfid_ranging.yaml (the node's own keys: RfidRangingNodeOptions).
  static RfidModelOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static RfidModelOptions fromYamlFile(const std::string& path, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();
  std::string validate() const;  // "" or "<key> = <value>: must be ..." (fromYaml and the model's constructor call it)
};

struct RfidResult {
  RfidRejection rejection = RfidRejection::kNone;
  std::string reason;
  std::optional<core::Observation> observation;   // positive, identifying (when accepted)
  std::vector<core::Observation> negative;        // negative observations of other pickers (may be empty)
  bool accepted() const { return rejection == RfidRejection::kNone; }
};

struct RfidCounters {
  std::size_t received = 0, accepted = 0, unknown_tag = 0, not_finite = 0, weak_signal = 0, out_of_order = 0,
              negative_sent = 0;
};

class RfidObservationModel {
 public:
  RfidObservationModel(core::PickerRegistry registry, std::shared_ptr<const topology::TopologicalMap> map,
                       RfidModelOptions options = {});

  RfidResult process(const RfidRead& read);
  // Forgets every time state (read spells, last reads, failed attempts): after the clock jumped back.
  void reset();
  // The pickers changed at run time (tpf_tracker's list): reads of a tag go to its wearer now, negative
  // information to every picker now tracked.
  void setRegistry(core::PickerRegistry registry) { registry_ = std::move(registry); }
  // The map edited at run time: read regions are found on `map` from the next read (no state names a node).
  void setMap(std::shared_ptr<const topology::TopologicalMap> map) {
    if (map) map_ = std::move(map);
  }
  // Map nodes inside the read region of an antenna at pose (x, y, yaw), sorted: within regionRadius() (and the
  // beam).
  std::vector<topology::NodeIndex> nodesInReadRegion(const Eigen::Vector3d& antenna_pose) const;
  // Radius of the read region: read_range (disc) or the cut-off radius r_c (logistic).
  double regionRadius() const { return region_radius_; }
  // p_read at planar distance d_xy from the antenna (disc model: 1 inside read_range, 0 outside).
  double readProbability(double planar_distance) const;

  const RfidCounters& counters() const { return counters_; }
  const RfidModelOptions& options() const { return options_; }

 private:
  std::vector<core::Observation> negativeObservations(const RfidRead& read, const std::string& read_picker);

  core::PickerRegistry registry_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  RfidModelOptions options_;
  bool logistic_ = true;
  double region_radius_ = 0.0;
  double position_variance_ = 0.0;  // per axis, of the read-region position (p_read-weighted)
  std::map<std::string, double> antenna_last_stamp_;                            // antenna -> newest read
  std::map<std::string, double> antenna_session_start_;  // antenna -> first read of its current reading spell
  std::map<std::pair<std::string, std::string>, double> last_read_;             // (antenna, picker) -> stamp
  std::map<std::pair<std::string, std::string>, double> last_negative_;         // (antenna, picker) -> stamp
  RfidCounters counters_;
};

}  // namespace sensors
}  // namespace picker_localisation
