// evaluator node: compares each picker's belief with its simulated ground truth (Navigate-and-Seek Sec. VI
// metrics, eval::computeError), publishes the live error and prints the error table at shutdown.
//   subscribes  /pickers/<id>/belief (picker_localisation/PickerBelief), /pickers/<id>/ground_truth
//               (geometry_msgs/PoseStamped) for every picker of ~pickers_file; the map as
//               ros_adapter::obtainMap
//   publishes   /pickers/<id>/error (picker_localisation/TrackingError), /diagnostics
//   parameters  ~pickers_file (required), ~sample_rate (1.0 Hz, ROS time), ~duration (0: none; s of ROS time
//   after
//               the first ground truth, then the table is printed and the node exits: end it with
//               required="true"), ~output_csv ("" none: per-sample CSV at exit), ~ordering_latency (1.5 s)
// Deterministic sampling (replay): samples fall on t_k = k / sample_rate of message time and are taken once ROS
// time passes t_k + ordering_latency, pairing the latest belief stamped <= t_k with the latest ground truth
// stamped <= t_k. So the errors depend on the messages' stamps, never on when a timer fired.
#pragma once

#include "picker_localisation/ros/node_diagnostics.h"
#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseStamped.h>

#include <ros/ros.h>

#include "picker_localisation/core/node_options.h"
#include "picker_localisation/ros/fleet_topics.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/stamp_guard.h"

#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "picker_localisation/PickerBelief.h"
#include "picker_localisation/eval/metrics.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

// The node's private parameters (see above). pickers_file falls back to the global /pickers_file.
struct EvaluatorOptions {
  std::string pickers_file;
  double sample_rate = 1.0;          // Hz of message time
  double duration = 0.0;             // s after the first ground truth, then the table and exit (0: none)
  std::string output_csv;            // "" none
  double ordering_latency = 1.5;     // s
  double max_truth_distance = 50.0;  // m, a truth farther from every node is not scored
  double max_future_stamp = 10.0;    // s
  std::string belief_topic = core::FleetTopicOptions().belief_topic;  // "" each picker's own belief topic
  std::string map_file, map_topic;  // the map source (core::CommonNodeOptions)

  // A bad value throws std::runtime_error "evaluator: <key> = <value>: must be ..."; an unknown key goes to
  // *unknown with the closest known one.
  static EvaluatorOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();  // every key fromYaml reads (its page's table)
  std::string validate() const;
};

class Evaluator {
 public:
  Evaluator(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  bool ok() const { return ok_; }
  // The table of every sample so far (eval::errorTable).
  std::string table() const;
  // Prints the table (ROS_INFO and stdout) and writes ~output_csv once.
  void finish();
  bool done() const { return done_; }

 private:
  struct Picker {
    std::string id;
    std::optional<std::string> estimated_node;  // latest at the last sample
    std::optional<Eigen::Vector2d> truth;
    std::deque<std::pair<double, std::string>> belief_history;     // (stamp, estimated node), by arrival
    std::deque<std::pair<double, Eigen::Vector2d>> truth_history;  // (stamp, position)
    ros::Subscriber truth_sub;
    ros::Publisher error_pub;
    std::vector<eval::ErrorSample> samples;
    std::size_t beliefs = 0, truths = 0, unknown_nodes = 0, not_finite = 0, off_map = 0, future = 0;
  };
  void onBelief(const picker_localisation::PickerBelief& msg);
  void onTruth(std::size_t i, const geometry_msgs::PoseStamped::ConstPtr& msg);
  void onTimer(const ros::TimerEvent& ev);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  bool ok_ = false, done_ = false, finished_ = false;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<MapFollower> map_follower_;
  std::vector<Picker> pickers_;
  std::map<std::string, std::size_t> index_;  // picker id -> pickers_ index
  std::unique_ptr<FleetBeliefs> beliefs_;     // ~belief_topic: the fleet stream, or "" per picker
  double duration_ = 0.0;
  double first_truth_ = -1.0;  // ROS time of the first ground truth, s
  double sample_period_ = 1.0, ordering_latency_ = 1.5;
  double next_sample_ = -1.0;  // next grid time t_k to sample, s
  double max_truth_distance_ = 50.0;  // m, a truth farther from every node is not scored (not snapped)
  double max_catch_up_ = 60.0;        // s, at most this much stamp time is sampled after a gap
  StampGuard clock_guard_;     // jump-back detection and stamps too far in the future
  void sampleAt(double t);
  std::string output_csv_;
  ros::Timer timer_;
  NodeDiagnostics diagnostics_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
