// farm_sim: the farm simulator (picker_localisation::sim::FarmSimulator) as a ROS node. It drives ROS time
// (/clock, faster than real time by ~rate_factor) and publishes tf, every raw sensor topic and the pickers'
// ground truth; /<robot>/goal retargets a robot. Parameters and topics: docs/readme/sim.md, config/sim.yaml.
#pragma once

#include <picker_localisation/CallStatusArray.h>
#include <picker_localisation/GoalNode.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include "picker_localisation/ros/node_diagnostics.h"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/sim/farm_simulator.h"

namespace picker_localisation {
namespace ros_adapter {

// The sensor mounts of a robot URDF template (config/robot/thorvald.urdf.in): links laser_*, rfid_*,
// uwb_anchor_*, camera_* (not *_optical) in base_link, projected to the plane (x, y, yaw) + height z. Base
// footprint size stays at the defaults. Throws std::runtime_error (one line) on a bad file or no lasers.
sim::RobotSensorLayout sensorLayoutFromUrdfTemplate(const std::string& path);

// The node's private parameters (docs/readme/sim.md). The simulator's own keys come from ~sim_config
// (config/sim.yaml, sim::loadSimConfig); the overrides below replace them when set.
struct FarmSimOptions {
  std::string sim_config, urdf_template, pickers_file, datum_file;
  std::string datum_source = "auto";  // auto | file | map (as gnss_ingest)
  std::optional<int> seed, robots;
  std::optional<double> robot_speed;
  std::optional<std::string> patrol;
  std::optional<bool> enable_gnss, enable_laser, enable_rfid, enable_uwb, enable_camera;
  // The call scenario (sim.yaml calls:): pickers fill trays, call on calls_topic and wait until the
  // dispatcher's status (call_status_topic) says their trays were loaded (to_storage, done or cancelled).
  std::optional<bool> calls;
  std::optional<double> tray_time_mean;
  std::string calls_topic = "/dispatcher/calls";         // PickerCall out
  std::string call_status_topic = "/dispatcher/status";  // CallStatusArray in
  double rate_factor = 10.0;  // simulated s per wall s (<= 0: as fast as possible)
  double duration = 0.0;      // simulated s, then the node exits (0: forever)
  double clock_step = 0.02;   // simulated s per tick
  double start_time = 100.0;  // ROS time of simulated t = 0, s
  double start_delay = 0.0;   // wall s the clock stays at start_time (repeated) before moving, so that nodes on
                              // simulated time (rosbag record waits to hear the clock) start and subscribe
  double ground_truth_rate = 10.0;  // Hz
  bool publish_sensor_frames = true;
  std::string map_frame = "map";

  // A bad value throws std::runtime_error "farm_sim: <key> = <value>: must be ..."; an unknown key goes to
  // *unknown with the closest known one.
  static FarmSimOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();  // every key fromYaml reads (its page's table)
  std::string validate() const;
  // The overrides applied to a configuration loaded from ~sim_config (throws on a bad ~patrol).
  void applyOverrides(sim::SimConfig& config) const;
};

class FarmSimNode {
 public:
  FarmSimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  // False when the configuration could not be loaded (the reason was logged as FATAL).
  bool ok() const { return static_cast<bool>(sim_); }
  // Runs until ~duration simulated seconds have passed (0: forever) or ROS shuts down.
  void run();
  // One tick: advance the simulation by ~clock_step and publish. Exposed for tests.
  void tick();

 private:
  struct RobotIo {
    ros::Publisher rfid, uwb, camera, truth;
    std::map<std::string, ros::Publisher> scans;  // by laser frame
    ros::Subscriber goal;
  };
  void publish(const sim::SimOutputs& out);
  void publishTf(const ros::Time& stamp);
  void publishStaticFrames();
  void publishGroundTruth(const ros::Time& stamp);
  void onGoal(std::size_t robot, const picker_localisation::GoalNode::ConstPtr& msg);
  void onCallStatus(const picker_localisation::CallStatusArray::ConstPtr& msg);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);
  ros::Time toRos(double sim_t) const { return ros::Time(start_time_ + sim_t); }

  ros::NodeHandle nh_, pnh_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<sim::FarmSimulator> sim_;
  core::PickerRegistry registry_;
  double start_time_ = 100.0, start_delay_ = 0.0, rate_factor_ = 10.0, duration_ = 0.0, clock_step_ = 0.02,
         truth_rate_ = 10.0;
  double last_truth_ = -1e9;
  std::string map_frame_ = "map";
  ros::Publisher clock_pub_;
  std::vector<ros::Publisher> fix_pubs_, truth_pubs_;
  std::vector<RobotIo> robots_;
  ros::Publisher calls_pub_;
  ros::Subscriber call_status_sub_;
  std::vector<double> waiting_since_;  // per picker: the stamp of its open call (NaN: not waiting)
  std::size_t n_calls_ = 0, n_released_ = 0;
  tf2_ros::TransformBroadcaster tf_;
  tf2_ros::StaticTransformBroadcaster static_tf_;
  bool publish_sensor_frames_ = true;
  NodeDiagnostics diagnostics_;
  std::size_t n_fix_ = 0, n_scan_ = 0, n_rfid_ = 0, n_uwb_ = 0, n_camera_ = 0, goals_accepted_ = 0,
              goals_rejected_ = 0;
  ros::WallTime wall_start_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
