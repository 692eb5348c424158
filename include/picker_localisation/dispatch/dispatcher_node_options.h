// The dispatcher node's parameters (one options struct: its own keys and the dispatcher's,
// config/dispatcher.yaml in one namespace). ROS-free, so the config test checks the shipped file against it.
#pragma once

#include <string>
#include <vector>

#include "picker_localisation/core/node_options.h"
#include "picker_localisation/dispatch/call_dispatcher.h"

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace dispatch {

// The node's private parameters: its own keys and the dispatcher's (config/dispatcher.yaml,
// dispatch::DispatcherOptions) in one namespace.
struct DispatcherNodeOptions {
  std::string pickers_file;         // config/pickers.yaml (required); then the tracker's list
  std::vector<std::string> robots;  // robot ids; empty: robot_1 .. robot_<num_robots>
  int num_robots = 1;
  std::string map_frame = "map";
  std::string base_frame = "{robot}/base_link";      // {robot} is replaced by the robot id
  double update_period = 1.0;                        // s of ROS time between dispatcher updates
  double max_pose_age = 5.0;                         // s: an older robot pose is not used (0: any age)
  std::string goal_topic = "call_goal";              // /<robot>/<this>, GoalNode
  std::string goal_pose_topic = "call_goal_pose";    // "" none
  std::string goal_node_topic = "call_goal_node";    // "" none
  std::string calls_topic = "~calls";                // PickerCall
  std::string car_topic = "/car/calls";              // std_msgs/String JSON of the CAR app ("" none)
  std::string rfid_topic = "rfid";                   // /<robot>/<this>, RfidReading ("" none)
  std::string observations_topic = "/observations";  // identified people (arrival) and the reported row out
  std::vector<std::string> arrival_sensors{"lidar", "lidar3d", "lidar_camera"};  // people sensors for arrival
  double max_fix_distance = 30.0;   // m from the nearest node: a call's fix farther away is off the map
  bool forward_fix = true;          // a call's fix goes on the picker's GNSS topic (a CAR app's only fix)
  double row_evidence_floor = 0.2;  // likelihood outside the reported row (1 inside); 1: the row is not used
  int closed_calls_kept = 20;       // done / cancelled calls still published on ~status
  // A farm's record of its calls: a CSV file, one line per call when it closes (done or cancelled) and for
  // the calls still open when the node stops ("" none). Columns: callLogHeader().
  std::string calls_log;
  std::string datum_file;           // for a call's fix when the map has no datum
  std::string datum_source = "auto";  // auto | file | map (as gnss_ingest)
  core::FleetTopicOptions fleet;      // belief_topic, registry_topic, registry_publisher
  core::CommonNodeOptions map_source;  // map_file, map_topic, map_timeout
  DispatcherOptions dispatcher;

  std::vector<std::string> robotIds() const;
  std::string baseFrame(const std::string& robot) const;
  std::string validate() const;  // "" or "<key> = <value>: must be ..."
  static DispatcherNodeOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();  // the node's own keys (not the dispatcher's)
};

}  // namespace dispatch
}  // namespace picker_localisation
