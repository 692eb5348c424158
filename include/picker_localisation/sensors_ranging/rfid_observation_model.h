// RFID reads of picker tags by a robot's antenna -> identifying Observations (Navigate-and-Seek Sec. IV/VI:
// an RFID detection is an identifying observation with gamma_RFID = 1). ROS-free.
//
// Positive model: a read of a picker's tag by an antenna at pose (x, y, yaw) in the map says the picker is
// within the antenna's read range: L(n) = 1 for every node n with |n - antenna| <= read_range and (for a
// directional antenna) |bearing(n) - yaw| <= beam_half_angle; other nodes 0 (not listed). When no node
// qualifies, the node nearest to the antenna gets L = 1 (an observation is never empty).
// Negative model (configurable): while an antenna is reading (it has produced reads with gaps shorter than
// `negative_window` s for at least `negative_window` s), every picker with RFID tags that this antenna has not read within `negative_window`
// gets, at most once per `negative_period` s, an identifying Observation (sent with each read)
// with L(n) = 1 - p_detect inside the read region and L(n) = 1 for every other map node (all map nodes are
// listed, because unlisted nodes mean L = 0). Limitation: an antenna that reads no tag at all is not known
// to be reading (RfidReading has no "inventory round" event), so it gives no negative information.
#pragma once

#include <Eigen/Core>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace sensors {

// One read, antenna pose already resolved into the map frame.
struct RfidRead {
  double stamp = 0.0;          // s
  std::string robot_id;
  std::string antenna_id;      // antenna frame name
  std::string tag_id;
  Eigen::Vector3d antenna_pose = Eigen::Vector3d::Zero();  // x, y (m), yaw (rad) in the map frame
  double rssi = 0.0;           // dBm
};

enum class RfidRejection { kNone = 0, kUnknownTag, kNotFinite, kWeakSignal, kOutOfOrder };
const char* toString(RfidRejection r);

struct RfidModelOptions {
  std::string sensor = "rfid";
  double read_range = 3.0;            // m, radius of the read region around the antenna
  double beam_half_angle = 3.14159265358979323846;  // rad, half opening of the read region (pi: omnidirectional)
  double min_rssi = -1e9;             // dBm, weaker reads are rejected as unreliable (default: accept all)
  bool negative_information = true;
  double negative_window = 5.0;       // s
  double negative_period = 5.0;       // s, at most one negative observation per picker and antenna per period
  double p_detect = 0.7;              // probability that a tag inside the read region is read within the window
  double out_of_order_tolerance = 0.0;  // s, reads older than the antenna's newest read by more are rejected
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
  // Map nodes inside the read region of an antenna at pose (x, y, yaw), sorted.
  std::vector<topology::NodeIndex> nodesInReadRegion(const Eigen::Vector3d& antenna_pose) const;

  const RfidCounters& counters() const { return counters_; }
  const RfidModelOptions& options() const { return options_; }

 private:
  std::vector<core::Observation> negativeObservations(const RfidRead& read, const std::string& read_picker);

  core::PickerRegistry registry_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  RfidModelOptions options_;
  std::map<std::string, double> antenna_last_stamp_;                            // antenna -> newest read
  std::map<std::string, double> antenna_session_start_;  // antenna -> first read of its current reading spell
  std::map<std::pair<std::string, std::string>, double> last_read_;             // (antenna, picker) -> stamp
  std::map<std::pair<std::string, std::string>, double> last_negative_;         // (antenna, picker) -> stamp
  RfidCounters counters_;
};

}  // namespace sensors
}  // namespace picker_localisation
