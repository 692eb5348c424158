// tpf_tracker: the Topological Particle Filter of one picker (Navigate-and-Seek Sec. IV) as a ROS node.
//
// Subscribes ~observations_topic (default /observations, picker_localisation/Observation): identifying
// observations only when their picker_id is this tracker's ~picker_id, non-identifying ones always.
// Publishes <prefix>/<id>/belief (PickerBelief), <prefix>/<id>/estimate
// (geometry_msgs/PoseWithCovarianceStamped, the MAP node's pose; covariance = mass-weighted spread of the
// belief's nodes), <prefix>/<id>/markers (MarkerArray: belief support coloured by mass, MAP node
// highlighted); prefix ~topic_prefix = /pickers. Services <prefix>/<id>/reset (ResetBelief) and
// <prefix>/<id>/what_if (WhatIf, on a copy of the filter). Periodic prediction at prediction_rate Hz of ROS
// time (ros::Timer: sim time and bags work) when no observation arrived for a period. Diagnostics: counts of
// accepted / reordered / dropped / rejected / other-picker observations, re-initialisations, health.
// Deterministic order (replay): observations wait ~ordering_latency seconds of ROS time (default 0.5; 0
// processes each on arrival) in a StampOrderedBuffer and are fused in stamp order, whichever publisher's
// message arrived first; periodic predictions fall on lastStamp + k / prediction_rate (never on the time a
// timer happened to fire) and are also made, in order, before an observation that comes later than that. So a
// bag replayed twice gives the same beliefs, provided messages arrive within the latency.
// Parameters (private): picker_id (required), map_file (else the latched topological_map topic),
// tpf_params_file (YAML like config/tpf.yaml) overridden key by key by private parameters with the same
// names (e.g. ~num_particles, ~method), seed (0: derived from picker_id), frame_id (map).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/ResetBelief.h>
#include <picker_localisation/WhatIf.h>
#include <visualization_msgs/MarkerArray.h>

#include <memory>
#include <string>

#include "picker_localisation/core/stamp_ordered_buffer.h"
#include "picker_localisation/ros/stamp_guard.h"
#include "picker_localisation/tpf/topological_particle_filter.h"

namespace picker_localisation {
namespace ros_adapter {

// TPF parameters from a private namespace: ~tpf_params_file (when set) as the base, then every private
// parameter named like a key of config/tpf.yaml on top. Throws std::runtime_error naming the key.
tpf::TpfParams tpfParamsFromRos(const ros::NodeHandle& pnh);

// Stable 64-bit seed from a picker id (FNV-1a), never 0.
std::uint64_t seedFromId(const std::string& id);

// Messages from a filter's belief (frame_id: map frame).
picker_localisation::PickerBelief toBeliefMsg(const tpf::Belief& belief, const topology::TopologicalMap& map,
                                              const std::string& picker_id, const std::string& frame_id);
geometry_msgs::PoseWithCovarianceStamped toEstimateMsg(const tpf::Belief& belief,
                                                       const topology::TopologicalMap& map,
                                                       const std::string& frame_id);
visualization_msgs::MarkerArray toMarkers(const tpf::Belief& belief, const topology::TopologicalMap& map,
                                          const std::string& picker_id, const std::string& frame_id);

class TpfTracker {
 public:
  TpfTracker(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  bool ok() const { return filter_ != nullptr; }

 private:
  void observationCallback(const picker_localisation::Observation::ConstPtr& msg);
  void timerCallback(const ros::TimerEvent&);
  void orderingCallback(const ros::TimerEvent&);
  // Fuses one observation after the periodic predictions that fall due before its stamp.
  void process(const core::Observation& obs, const std::string& sensor);
  // Periodic predictions at lastStamp + k * period up to `until` (s).
  void predictDueUntil(double until);
  bool reset(picker_localisation::ResetBelief::Request&, picker_localisation::ResetBelief::Response& res);
  bool whatIf(picker_localisation::WhatIf::Request& req, picker_localisation::WhatIf::Response& res);
  void publish();
  static constexpr int kMaxPredictionsPerCall = 100;  // a longer silence is bridged by one prediction
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  std::string picker_id_, frame_id_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<tpf::TopologicalParticleFilter> filter_;
  ros::Subscriber sub_;
  ros::Publisher belief_pub_, estimate_pub_, markers_pub_;
  ros::ServiceServer reset_srv_, what_if_srv_;
  ros::Timer timer_, diagnostics_timer_, ordering_timer_;
  core::StampOrderedBuffer<std::pair<core::Observation, std::string>> ordering_;
  double ordering_latency_ = 0.5;
  diagnostic_updater::Updater diagnostics_;
  double prediction_period_ = 0.0;
  std::uint64_t received_ = 0, other_picker_ = 0, unknown_nodes_ = 0, what_if_calls_ = 0, resets_ = 0;
  StampGuard stamp_guard_;
  // The clock jumped back (bag loop, simulator restart): the belief and the waiting observations are dropped
  // so the next observation initialises the filter again (its stamps would all be "too old" otherwise).
  void checkClockJump();
  std::uint64_t last_reported_problems_ = 0, last_diag_received_ = 0;
  ros::WallTime last_diag_time_;
  std::string last_problem_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
