// GNSS fixes of one picker -> identifying Observations over map nodes (Navigate-and-Seek Sec. IV/VI; outlier
// gating after Periotto and Sartori). ROS-free: the node converts sensor_msgs/NavSatFix into core::GnssFix, and the
// offline experiment runner feeds the simulator's core::GnssFix directly.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/sensor_data.h"
#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/sensors_ranging/gnss_bias.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace sensors {

enum class GnssRejection {
  kNone = 0,
  kNoFix,               // status NO_FIX (-1) or below
  kNotFinite,           // NaN/Inf latitude / longitude / stamp / used covariance, or lat/lon out of range
  kNegativeCovariance,  // a negative horizontal variance, or a horizontal block that is not PSD
  kOutOfOrder,          // stamp <= the stamp of the last accepted fix (repeated or going backwards)
  kImpossibleJump,      // fails the jump gate (see GnssIngestOptions)
  kOffMap,              // farther than max_map_distance from every map node (not snapped to the nearest)
};
const char* toString(GnssRejection r);

// Identity for anonymous people detections (LiDAR legs, camera-fused legs): see picker_association.h. Keys
// association_<name> (enabled: associate_people) of config/gnss_ingest.yaml.
struct PickerAssociationOptions {
  bool enabled = true;               // associate anonymous people observations with pickers
  double clutter_density = 5e-4;     // 1/m^2, density of people detections that are no listed picker (false
                                     // legs, other workers): the "nobody we track" hypothesis
  double min_probability = 0.8;      // association probability at which a detection identifies its picker
  double sighting_min_probability = 0.0;  // a named detection is a bias sighting of its picker only at this
                                          // probability or more (below min_probability: every named one)
  // A bias sighting from a named detection weighs in with its probability (PDAF, GnssBiasEstimator::update).
  bool weigh_sightings = false;
  double min_candidate_probability = 0.05;  // an unidentified detection reaches the trackers of the pickers
                                     // with at least this probability (0: every tracker, as the paper)
  double belief_weight = 0.5;        // share of the tracker's belief in the picker's predicted position
                                     // (the rest: the bias-corrected fix); 0 = fix only
  double belief_sigma = 1.0;         // m, spread of a belief node's mass around the node (half a node spacing
                                     // plus the picker's offset from the lane centre line)
  double max_fix_age = 30.0;         // s, an older fix does not predict the picker (belief only)
  double speed = 0.7;                // m/s, picker speed that spreads the prediction with the fix's age
  double belief_lag = 2.0;           // s, the belief used is the newest one stamped at least this long before
                                     // the detection (>= the trackers' ordering latency: deterministic replay)
  double max_belief_age = 10.0;      // s, an older belief (beyond the lag) is not used
  // Identity evidence (picker_association.h, IdentityEvidence): the newest identifying observation of each of
  // these sensors per picker and robot (an RFID read, the failed reads of an antenna that is reading, a UWB
  // range) weighs "this detection is picker i" by how much better it explains that observation than the
  // picker's predicted position does. Empty: not used.
  std::vector<std::string> identity_sensors{"rfid", "uwb"};
  double identity_window = 5.0;  // s, evidence older (or newer) than this around the detection is not used
  double identity_floor = 0.02;  // floor on both sides of the ratio: one observation changes l_i by at
                                 // most 1 / floor either way
  bool isIdentitySensor(const std::string& sensor) const;

  static PickerAssociationOptions fromYaml(const YAML::Node& node);
  static const std::vector<std::string>& yamlKeys();
  std::string validate() const;
};

struct GnssIngestOptions {
  std::string sensor = "gnss";      // Observation::sensor
  double default_sigma = 3.0;       // m, per axis, used when covariance_type is UNKNOWN (0)
  double min_sigma = 1.0;           // m, floor on every standard deviation of the likelihood
  double cutoff_sigmas = 3.0;       // nodes farther than this many sigmas are left out of the likelihood
  std::size_t max_nodes = 0;        // keep at most this many most likely nodes (0: no limit)
  std::size_t velocity_window = 10; // velocity from the last N accepted fixes (paper: 10); < 2 disables it
  // Impossible-jump gate (Mahalanobis, after Periotto and Sartori): with d the displacement from the last accepted fix,
  // dt its age and C = C_last + C_new + (max_speed * dt)^2 I, a fix is rejected when d^T C^-1 d > gate^2.
  // After `jump_reset_count` consecutive jump rejections the gate re-anchors on the newest fix (so one bad
  // reference cannot lock the picker out); the gate is also skipped after a blackout.
  double max_speed = 3.0;           // m/s, fastest plausible picker speed (running)
  double jump_gate_sigmas = 5.0;    // gate in standard deviations (0 disables the gate)
  std::size_t jump_reset_count = 5;
  double blackout_timeout = 10.0;   // s without an accepted fix = blackout (velocity window restarts after it)
  // A fix this far (m) from every map node says nothing about the map: it is rejected before the jump gate, so
  // it neither re-anchors the gate nor snaps the belief to the nearest node (a 50 km glitch moved it 23 m).
  // 0 disables. 50 m: ten times the worst Table I bias, beyond any lane a picker can be in.
  double max_map_distance = 50.0;
  // True when `p` (map frame) is farther than max_map_distance from every node of `map` (never when 0); the
  // distance goes to *distance. One rule for fixes, picker poses and other detectors' people.
  bool farFromMap(const topology::TopologicalMap& map, const Eigen::Vector2d& p, double* distance = nullptr) const {
    if (!(max_map_distance > 0.0) || map.numNodes() == 0) return false;
    const double d = map.distanceToNearestNode(p);
    if (distance) *distance = d;
    return d > max_map_distance;
  }
  GnssBiasOptions bias;             // the device's bias estimate (gnss_bias.h), keys bias_*
  PickerAssociationOptions association;  // identity of anonymous people detections, keys association_*

  // The keys of config/gnss_ingest.yaml (the gnss_ingest node's private parameters; node-only keys such as
  // topics are accepted and ignored). Missing keys keep the defaults; a bad value throws std::runtime_error
  // naming the key; `unknown` receives one message per unknown key (with the closest known one).
  static GnssIngestOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static GnssIngestOptions fromYamlFile(const std::string& path, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();  // the algorithm's keys (bias and association included)
  std::string validate() const;  // "" or "<key> = <value>: must be ..."
  // cutoff_sigmas, min_sigma, max_nodes as core::setGaussianLikelihood takes them.
  core::GaussianLikelihoodOptions likelihoodOptions() const {
    core::GaussianLikelihoodOptions lo;
    lo.cutoff_sigmas = cutoff_sigmas;
    lo.min_sigma = min_sigma;
    lo.max_nodes = max_nodes;
    return lo;
  }
};

// Result of one fix.
struct GnssResult {
  GnssRejection rejection = GnssRejection::kNone;
  std::string reason;                       // one line for the log when rejected
  std::optional<core::Observation> observation;  // set when accepted
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // raw fix, map frame, m (when the lat/lon were usable)
  bool bias_corrected = false;              // the observation's likelihood is centred on position - bias
  double blackout_ended = 0.0;              // s, length of the blackout this fix ended (0: none)
  bool accepted() const { return rejection == GnssRejection::kNone; }
};

struct GnssCounters {
  std::size_t received = 0, accepted = 0, no_fix = 0, not_finite = 0, negative_covariance = 0, out_of_order = 0,
              impossible_jump = 0, off_map = 0, gate_resets = 0, blackouts = 0;
  double longest_blackout = 0.0;  // s
};

// One picker's GNSS stream. The likelihood is core::setGaussianLikelihood over the map nodes with the fix's
// horizontal covariance rotated into the map frame (configured sigma when UNKNOWN), floored at min_sigma:
// L(n) = exp(-0.5 d^T C^-1 d) (unitless, peak 1), d = node - fix (m). The velocity is the mean velocity over
// the window, (p_last - p_first) / (t_last - t_first) (= the time-weighted mean of the step velocities).
class GnssIngest {
 public:
  GnssIngest(std::string picker_id, std::shared_ptr<const topology::TopologicalMap> map, core::GeodeticDatum datum,
             GnssIngestOptions options = {});

  GnssResult process(const core::GnssFix& fix);

  // A metric sighting of this picker (position, covariance, map frame) by an identifying sensor or an
  // associated people detection at time `stamp`: pairs it with the raw fix nearest in time (within
  // bias_pairing_gap) and updates the bias estimate with y = fix - position,
  // R = cov + residual_std^2 I + (pairing_speed * gap)^2 I.
  // `probability`: that the sighting is this picker's (GnssBiasEstimator::update).
  BiasUpdate addSighting(double stamp, const Eigen::Vector2d& position, const Eigen::Matrix2d& covariance,
                         double probability = 1.0);

  // Where the GNSS says the picker is at time t: the latest accepted fix minus the bias estimate, with
  // covariance P_bias(t) + residual_std^2 I + (speed * age)^2 I (prior bias covariance before any sighting).
  struct Prediction {
    bool valid = false;  // false before the first fix or when the fix is older than max_age
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
  };
  Prediction predictPosition(double t, double speed, double max_age) const;
  const GnssBiasEstimator& bias() const { return bias_; }

  // True when no fix was accepted within blackout_timeout before `now` (s; message / sim time). False before
  // the first accepted fix.
  bool inBlackout(double now) const;
  // Seconds since the last accepted fix (+inf before the first).
  double ageOfLastFix(double now) const;

  // The map edited at run time: fixes are placed on `map` from now on. A changed datum (`datum_moved`) moves
  // the map frame, so the fix history (positions in the old frame) is forgotten, as after a blackout; the
  // bias estimate, a vector east-north, holds in both frames and is kept.
  void setMap(std::shared_ptr<const topology::TopologicalMap> map, const core::GeodeticDatum& datum,
              bool datum_moved);

  const GnssCounters& counters() const { return counters_; }
  const std::string& pickerId() const { return picker_id_; }
  const core::GeodeticDatum& datum() const { return datum_; }
  const GnssIngestOptions& options() const { return options_; }

 private:
  static constexpr std::size_t kRecentFixes = 10;
  bool horizontalCovariance(const core::GnssFix& fix, Eigen::Matrix2d& c_en, GnssRejection& rejection,
                            std::string& why) const;
  bool passesJumpGate(const Eigen::Vector2d& p, const Eigen::Matrix2d& c_map, double dt, std::string& why);
  core::Observation observationOf(double stamp, const Eigen::Vector2d& p, const Eigen::Matrix2d& c_map,
                                  bool* bias_corrected) const;
  struct Accepted {
    double stamp;
    Eigen::Vector2d position;
    Eigen::Matrix2d covariance;
  };
  std::string picker_id_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  core::GeodeticDatum datum_;
  GnssIngestOptions options_;
  std::deque<Accepted> window_;     // last accepted fixes (newest at the back)
  std::deque<Accepted> recent_;     // last raw fixes for pairing sightings (kept through blackouts)
  GnssBiasEstimator bias_;
  std::optional<Accepted> last_;    // last accepted fix
  std::size_t consecutive_jumps_ = 0;
  GnssCounters counters_;
};

}  // namespace sensors
}  // namespace picker_localisation
