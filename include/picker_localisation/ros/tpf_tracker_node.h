// tpf_tracker: the Topological Particle Filters of a whole farm's pickers in one node, one TPF per picker
// (Navigate-and-Seek Sec. IV).
//
// Pickers: ~pickers_file (config/pickers.yaml: every entry, each with its optional `tpf:` overrides) or one
// ~picker_id; more are added and removed at run time with the services ~add_picker (AddPicker),
// ~remove_picker (RemovePicker) and ~list_pickers (ListPickers). A bad request (invalid, empty or duplicate
// id, an empty tag or one another picker wears, a bad GNSS topic name, bad overrides) is refused with a
// message and changes nothing. Started from a pickers file, the current list is latched on <prefix>/registry
// (PickerList), which gnss_ingest, rfid_ranging and uwb_ranging follow (not with one ~picker_id, which names
// no GNSS topic). Per picker: <prefix>/<id>/belief (PickerBelief), <prefix>/<id>/estimate
// (geometry_msgs/PoseWithCovarianceStamped, the MAP node's pose; covariance = mass-weighted spread of the
// belief's nodes), <prefix>/<id>/markers (MarkerArray: belief support coloured by mass, MAP node highlighted;
// built only while someone subscribes), <ns>/<id>/current_node (std_msgs/String, the MAP node's name, on
// change: what LCAS coordination reads of an agent; ns ~current_node_namespace, default the prefix, "/" for
// /<id>/current_node, "" none); services <prefix>/<id>/reset (ResetBelief) and <prefix>/<id>/what_if
// (WhatIf, on a copy of the filter); prefix ~topic_prefix = /pickers. Each topic behaves as latched (a new
// subscriber gets the current message at once) but costs nothing while nobody listens (LastValuePublisher).
// Every picker's beliefs also stream on <prefix>/beliefs (PickerBeliefArray, not latched): one connection for
// a consumer of the whole fleet (gnss_ingest), and under load one message per burst of beliefs. Routing: one
// subscription to ~observations_topic (/observations); each message is decoded once and goes to the one
// filter it identifies, to its candidate pickers, or (anonymous, no candidates) to every filter
// (core::concernsPicker's rule, by lookup).
// Time: periodic prediction at each picker's prediction_rate (ROS time, one timer for all pickers) when no
// observation arrived for a period, on lastStamp + k / prediction_rate (never on the time a timer fired).
// ~ordering_latency: observations wait that many seconds of ROS time and are fused in stamp order, whichever
// publisher's message arrived first, so a bag replayed twice gives the same beliefs. Default -1 = automatic:
// 0.5 s under /use_sim_time (bags, simulator: deterministic replay), 0 live (each observation fused on
// arrival, within milliseconds; one that arrives late, within reorder_window, is fused at the filter's
// current time, as the filter documents). Clock jumps back reset every belief.
// Above ~on_demand_topics_above pickers (default 100) the per-picker topics are advertised only while some
// node subscribes to them (the master is polled every ~demand_poll_period, 2 s; a new subscriber gets the
// current message on connect): roscpp's per-message cost grows with the publications of a process, and a
// farm's thousands of unwatched topics made that cost larger than the filters'. Subscribe to any of them
// (rviz, rostopic echo) and it appears within the poll period. The fleet stream is always advertised.
// Diagnostics: one status for the fleet and one per picker.
// Map: ~map_file, else the latched map topic, followed for the node's life: an edited map is adopted by every
// filter (adoptMap), a malformed one refused (MapFollower).
// Parameters (private): pickers_file or picker_id, map_file (else the latched topological_map topic),
// tpf_params_file (YAML like config/tpf.yaml) overridden key by key by private parameters with the same
// names (e.g. ~num_particles, ~method) and then by a picker's own overrides, seed (each picker's filter is
// seeded from its id, mixed with ~seed when > 0: tpf::TrackerFleet::seedFor, as the runner's --tracker-seed),
// frame_id (map), max_future_stamp (10 s).
#pragma once

#include "picker_localisation/ros/node_diagnostics.h"
#include <ros/ros.h>
#include <std_msgs/String.h>

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/PickerBeliefArray.h>
#include <picker_localisation/ResetBelief.h>
#include <picker_localisation/WhatIf.h>
#include <picker_localisation/AddPicker.h>
#include <picker_localisation/ListPickers.h>
#include <picker_localisation/RemovePicker.h>
#include <visualization_msgs/MarkerArray.h>

#include <yaml-cpp/yaml.h>

#include <map>
#include <optional>
#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/core/stamp_ordered_buffer.h"
#include "picker_localisation/ros/belief_conversions.h"
#include "picker_localisation/ros/last_value_publisher.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/stamp_guard.h"
#include "picker_localisation/tpf/tpf_tracker_node_options.h"
#include "picker_localisation/tpf/tracker_fleet.h"

namespace picker_localisation {
namespace ros_adapter {

// The merged TPF parameters YAML of a private namespace: ~tpf_params_file (when set) as the base, then every
// private parameter on top. Throws std::runtime_error naming the file on a YAML error.
YAML::Node tpfYamlFromRos(const ros::NodeHandle& pnh);
// `base` with a picker's overrides (YAML mapping text, "" none) on top, through the same schema and bounds as
// config/tpf.yaml (tpf::TpfParams::fromYaml). Throws std::runtime_error naming the key on a bad value, and on
// overrides longer than kMaxOverridesChars or with more than twice as many keys as the file has. With
// `unknown`, one message per override key that is not a config/tpf.yaml key, with the closest one.
constexpr std::size_t kMaxOverridesChars = 16384;
tpf::TpfParams tpfParamsWithOverrides(const YAML::Node& base, const std::string& overrides,
                                      std::vector<std::string>* unknown = nullptr);

class TpfTracker {
 public:
  TpfTracker(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  ~TpfTracker();
  bool ok() const { return ok_; }
  std::size_t size() const { return tracks_.size(); }

 private:
  bool loadOptionsAndPickers(const ros::NodeHandle& pnh, tpf::TpfTrackerNodeOptions& out);
  struct Track;      // one picker's topics, services and adapter counters (its filter is the fleet's)
  struct Outgoing {  // one belief's messages, queued by publish() and sent by flush()
    Track* track;
    picker_localisation::PickerBelief belief;
    std::optional<geometry_msgs::PoseWithCovarianceStamped> estimate;
    std::optional<visualization_msgs::MarkerArray> markers;
    std::optional<std_msgs::String> current_node;
  };
  struct Pending {
    core::Observation obs;
    std::string sensor;
  };
  // Starts tracking a picker; false and *error, nothing changed, when its parameters are bad or its filter
  // cannot be allocated. Unknown override keys are appended to *unknown.
  bool startTrack(const core::PickerConfig& picker, std::string* error, std::vector<std::string>* unknown);
  // The tracks an observation concerns.
  std::vector<Track*> route(bool identifying, const std::string& picker_id, const std::vector<std::string>& candidates);
  void observationCallback(const picker_localisation::Observation::ConstPtr& msg);
  void dispatch(const Pending& p);
  void predictionTick(const ros::TimerEvent&);
  void orderingTick(const ros::TimerEvent&);
  // One throttled log line for a refused observation, an exception or a re-initialisation.
  void report(const tpf::TrackerFleet::Outcome& outcome, const std::string& sensor);
  void publish(Track& t);
  void flush();
  void flushWhenIdle();
  void publishRegistry();
  void updatePredictionTimer();
  void advertiseTopics(Track& t);
  bool addPicker(picker_localisation::AddPicker::Request& req, picker_localisation::AddPicker::Response& res);
  bool removePicker(picker_localisation::RemovePicker::Request& req,
                    picker_localisation::RemovePicker::Response& res);
  bool listPickers(picker_localisation::ListPickers::Request& req,
                   picker_localisation::ListPickers::Response& res);
  static constexpr double kMaxWhatIfHorizon = 3600.0;  // s: a planner asks seconds to minutes ahead
  void diagnoseFleet(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnose(Track& t, diagnostic_updater::DiagnosticStatusWrapper& stat);
  // The clock jumped back (bag loop, simulator restart): every belief and the waiting observations are dropped
  // so the next observation initialises each filter again (its stamps would all be "too old" otherwise).
  void checkClockJump();
  // A new map from the map topic (MapFollower): every filter moves onto it (particles on removed or renamed
  // nodes to the nearest node of the new map, velocities and bias states kept) and republishes at once, so
  // current_node names a node of the new map.
  void adoptMap(std::shared_ptr<const topology::TopologicalMap> map, const topology::MapChange& change);

  bool ok_ = false;
  ros::NodeHandle nh_;
  std::string frame_id_, prefix_, current_node_ns_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  YAML::Node base_params_;
  int seed_param_ = 0;
  core::PickerRegistry registry_;
  std::unique_ptr<tpf::TrackerFleet> fleet_;  // every picker's filter and the prediction schedule
  std::map<std::string, std::unique_ptr<Track>> tracks_;
  ros::Subscriber sub_;
  ros::Publisher registry_pub_;
  CountedPublisher fleet_pub_;
  std::vector<Outgoing> outgoing_;
  bool flush_scheduled_ = false;
  OnDemandTopics on_demand_;
  ros::ServiceServer add_srv_, remove_srv_, list_srv_;
  ros::Timer prediction_timer_, ordering_timer_;
  double timer_period_ = 0.0;
  core::StampOrderedBuffer<Pending> ordering_;
  double ordering_latency_ = 0.0;
  NodeDiagnostics diagnostics_;
  std::uint64_t received_ = 0, unrouted_ = 0, added_ = 0, removed_ = 0, refused_requests_ = 0, oversized_ = 0;
  StampGuard stamp_guard_;
  std::unique_ptr<MapFollower> map_follower_;
  std::uint64_t map_updates_ = 0;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
