// The nbs_planner node's options: its own keys, the shared node keys (core::CommonNodeOptions), the fleet
// helpers' keys it uses, and the planner's (config/nbs.yaml, nbs::PlannerConfig). The offline runner reads
// the same file through it (planning_period, battery_level, what_if_seed as the node does). ROS-free.
#pragma once

#include <string>
#include <vector>

#include "picker_localisation/core/node_options.h"
#include "picker_localisation/nbs/next_best_sense_planner.h"

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace nbs {

struct NbsPlannerNodeOptions {
  core::CommonNodeOptions common;  // map_frame, tf_timeout, the map source
  core::FleetTopicOptions fleet;   // pickers_file (required by the node), belief_topic, registry
  std::string robot_id;            // "" the node's namespace (robot_1 in the root namespace)
  std::string base_frame = "{robot_id}/base_link";  // {robot_id} is replaced by the robot id
  double planning_period = 5.0;                     // s of ROS time between plans
  double claim_timeout = 30.0;            // s: another robot's goal older than this is no longer a claim
  double max_pose_age = 5.0;              // s: an older robot pose is not planned from (0: any age)
  double battery_level = 1.0;             // [0, 1] until a BatteryState arrives
  bool use_what_if = true;                // predictions from /pickers/<id>/what_if (false: belief held still)
  int what_if_seed = 1;                   // seed of every what-if query
  std::vector<std::string> fleet_robots;  // key `fleet`: the robots' ids ([] robot_1 .. robot_<num_robots>)
  int num_robots = 1;
  std::string battery_topic = "battery";      // BatteryState, robot namespace ("" none)
  std::string goal_pose_topic = "goal_pose";  // the goal as PoseStamped, latched ("" none)
  std::string call_goal_topic = "call_goal";  // the dispatcher's goal while serving a call ("" none)
  // The dispatcher's calls (CallStatusArray): when each picker's trays were emptied, for the planner's
  // call-due weights (call_due_weight; "" none: every picker counted from the node's start).
  std::string call_status_topic = "/dispatcher/status";
  PlannerConfig planner;                      // config/nbs.yaml's planner keys

  std::string robotId(const std::string& node_namespace) const;  // robot_id, else the namespace, else robot_1
  std::string baseFrame(const std::string& robot) const;
  std::vector<std::string> robotIds() const;  // fleet_robots, else robot_1 .. robot_<num_robots>
  std::string validate() const;               // "" or "<key> = <value>: must be ..."
  // Throws std::runtime_error naming the key on a bad value; *messages gets one line per unknown key (the
  // planner's sections included) and per deprecated name.
  static NbsPlannerNodeOptions fromYaml(const YAML::Node& node, std::vector<std::string>* messages = nullptr);
  static NbsPlannerNodeOptions fromYamlFile(const std::string& path,
                                            std::vector<std::string>* messages = nullptr);
  static const std::vector<std::string>& yamlKeys();  // the node's own and fleet keys (its page's table)
};

}  // namespace nbs
}  // namespace picker_localisation
