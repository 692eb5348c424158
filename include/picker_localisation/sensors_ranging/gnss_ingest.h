// GNSS fixes of one picker -> identifying Observations over map nodes (Navigate-and-Seek Sec. IV/VI; outlier
// gating after seed 002). ROS-free: the node converts sensor_msgs/NavSatFix into GnssFix, and the offline
// experiment runner can feed GnssFix directly.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/sensors_ranging/geodetic_datum.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace sensors {

// A GNSS fix as in sensor_msgs/NavSatFix, without ROS types.
struct GnssFix {
  double stamp = 0.0;       // s, the fix's own time stamp
  double latitude = 0.0;    // deg WGS84
  double longitude = 0.0;   // deg WGS84
  double altitude = 0.0;    // m (NaN allowed: not used for the horizontal position then)
  int status = 0;           // NavSatStatus: -1 NO_FIX, 0 FIX, 1 SBAS_FIX, 2 GBAS_FIX
  std::array<double, 9> covariance{};  // row-major ENU position covariance, m^2
  int covariance_type = 0;  // 0 UNKNOWN, 1 APPROXIMATED, 2 DIAGONAL_KNOWN, 3 KNOWN
};

enum class GnssRejection {
  kNone = 0,
  kNoFix,               // status NO_FIX (-1) or below
  kNotFinite,           // NaN/Inf latitude / longitude / stamp / used covariance, or lat/lon out of range
  kNegativeCovariance,  // a negative horizontal variance, or a horizontal block that is not PSD
  kOutOfOrder,          // stamp <= the stamp of the last accepted fix (repeated or going backwards)
  kImpossibleJump,      // fails the jump gate (see GnssIngestOptions)
};
const char* toString(GnssRejection r);

struct GnssIngestOptions {
  std::string sensor = "gnss";      // Observation::sensor
  double default_sigma = 3.0;       // m, per axis, used when covariance_type is UNKNOWN (0)
  double min_sigma = 1.0;           // m, floor on every standard deviation of the likelihood
  double cutoff_sigmas = 3.0;       // nodes farther than this many sigmas are left out of the likelihood
  std::size_t max_nodes = 0;        // keep at most this many most likely nodes (0: no limit)
  std::size_t velocity_window = 10; // velocity from the last N accepted fixes (paper: 10); < 2 disables it
  // Impossible-jump gate (Mahalanobis, after seed 002): with d the displacement from the last accepted fix,
  // dt its age and C = C_last + C_new + (max_speed * dt)^2 I, a fix is rejected when d^T C^-1 d > gate^2.
  // After `jump_reset_count` consecutive jump rejections the gate re-anchors on the newest fix (so one bad
  // reference cannot lock the picker out); the gate is also skipped after a blackout.
  double max_speed = 3.0;           // m/s, fastest plausible picker speed (running)
  double jump_gate_sigmas = 5.0;    // gate in standard deviations (0 disables the gate)
  std::size_t jump_reset_count = 5;
  double blackout_timeout = 10.0;   // s without an accepted fix = blackout (velocity window restarts after it)

  // The keys of config/gnss_ingest.yaml (the gnss_ingest node's private parameters; node-only keys such as
  // topics are accepted and ignored). Missing keys keep the defaults; a bad value throws std::runtime_error
  // naming the key; `unknown` receives one message per unknown key (with the closest known one).
  static GnssIngestOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static GnssIngestOptions fromYamlFile(const std::string& path, std::vector<std::string>* unknown = nullptr);
  std::string validate() const;  // "" or "<key> = <value>: must be ..."
};

// Result of one fix.
struct GnssResult {
  GnssRejection rejection = GnssRejection::kNone;
  std::string reason;                       // one line for the log when rejected
  std::optional<core::Observation> observation;  // set when accepted
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // map frame, m (when the lat/lon were usable)
  double blackout_ended = 0.0;              // s, length of the blackout this fix ended (0: none)
  bool accepted() const { return rejection == GnssRejection::kNone; }
};

struct GnssCounters {
  std::size_t received = 0, accepted = 0, no_fix = 0, not_finite = 0, negative_covariance = 0, out_of_order = 0,
              impossible_jump = 0, gate_resets = 0, blackouts = 0;
  double longest_blackout = 0.0;  // s
};

// One picker's GNSS stream. The likelihood is core::setGaussianLikelihood over the map nodes with the fix's
// horizontal covariance rotated into the map frame (configured sigma when UNKNOWN), floored at min_sigma:
// L(n) = exp(-0.5 d^T C^-1 d) (unitless, peak 1), d = node - fix (m). The velocity is the mean velocity over
// the window, (p_last - p_first) / (t_last - t_first) (= the time-weighted mean of the step velocities).
class GnssIngest {
 public:
  GnssIngest(std::string picker_id, std::shared_ptr<const topology::TopologicalMap> map, GeodeticDatum datum,
             GnssIngestOptions options = {});

  GnssResult process(const GnssFix& fix);
  // True when no fix was accepted within blackout_timeout before `now` (s; message / sim time). False before
  // the first accepted fix.
  bool inBlackout(double now) const;
  // Seconds since the last accepted fix (+inf before the first).
  double ageOfLastFix(double now) const;

  const GnssCounters& counters() const { return counters_; }
  const std::string& pickerId() const { return picker_id_; }
  const GeodeticDatum& datum() const { return datum_; }
  const GnssIngestOptions& options() const { return options_; }

 private:
  struct Accepted {
    double stamp;
    Eigen::Vector2d position;
    Eigen::Matrix2d covariance;
  };
  std::string picker_id_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  GeodeticDatum datum_;
  GnssIngestOptions options_;
  std::deque<Accepted> window_;     // last accepted fixes (newest at the back)
  std::optional<Accepted> last_;    // last accepted fix
  std::size_t consecutive_jumps_ = 0;
  GnssCounters counters_;
};

}  // namespace sensors
}  // namespace picker_localisation
