// nbs_planner: the Next-Best-Sense planner of one robot (Navigate-and-Seek Sec. V), run in the robot's
// namespace. Reads the trackers' beliefs from their fleet stream ~belief_topic (/pickers/beliefs; "" = each
// /pickers/<id>/belief) for the pickers of ~pickers_file, then of the tracker's list (~registry_topic,
// /pickers/registry: pickers added or removed at run time), the goals of the other robots of the fleet
// (/<robot_k>/goal) and, optionally, ~battery_topic; reads the robot pose from tf (map ->
// <robot_id>/base_link). Every ~planning_period s of ROS time it plans (NextBestSensePlanner, policy nbs or
// estimated_node) and publishes the goal on goal (GoalNode, latched) and the candidates' utilities on
// nbs_candidates (MarkerArray); service get_candidates returns the ranked candidates. Predictions and
// hypothetical posteriors come from the trackers' /pickers/<id>/what_if services. While the robot serves a
// call, the dispatcher's goal (~call_goal_topic, default call_goal) is the robot's goal and no plan is made;
// an empty call goal hands the robot back. No ground-truth topic is read. Parameters: config/nbs.yaml.
#pragma once

#include "picker_localisation/ros/node_diagnostics.h"
#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <picker_localisation/CallStatusArray.h>
#include <picker_localisation/GetCandidates.h>
#include <picker_localisation/GoalNode.h>
#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/WhatIf.h>
#include <sensor_msgs/BatteryState.h>
#include <visualization_msgs/MarkerArray.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "picker_localisation/nbs/next_best_sense_planner.h"
#include "picker_localisation/ros/fleet_topics.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/stamp_guard.h"

namespace picker_localisation {
namespace ros_adapter {

class NbsPlannerNode {
 public:
  NbsPlannerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  bool ok() const { return ok_; }
  // One planning cycle (also run by the timer). Public for tests.
  void planOnce();

 private:
  struct PickerInput {
    std::string id;
    ros::ServiceClient what_if;
    std::optional<picker_localisation::PickerBelief> belief;
    std::size_t received = 0, rejected = 0;
  };
  struct PeerGoal {
    picker_localisation::GoalNode msg;
    ros::Time received;
  };

  void beliefCallback(const picker_localisation::PickerBelief& msg);
  void applyPickerList(const std::vector<std::string>& ids);
  void peerGoalCallback(const picker_localisation::GoalNode::ConstPtr& msg);
  void callGoalCallback(const picker_localisation::GoalNode::ConstPtr& msg);
  void callStatusCallback(const picker_localisation::CallStatusArray::ConstPtr& msg);
  void forwardCallGoal(const ros::Time& stamp);
  void publishGoal(const picker_localisation::GoalNode& goal);  // on goal and goal_pose
  void batteryCallback(const sensor_msgs::BatteryState::ConstPtr& msg);
  bool getCandidates(picker_localisation::GetCandidates::Request& req,
                     picker_localisation::GetCandidates::Response& res);
  std::optional<topology::NodeIndex> robotNode();
  void publish(const nbs::PlanResult& plan, const ros::Time& stamp);
  visualization_msgs::MarkerArray candidateMarkers(const nbs::PlanResult& plan, const ros::Time& stamp) const;
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  bool ok_ = false;
  ros::NodeHandle nh_, pnh_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<nbs::NextBestSensePlanner> planner_;
  std::unique_ptr<MapFollower> map_follower_;
  std::string robot_id_, map_frame_, base_frame_;
  double battery_level_ = 1.0;
  double claim_timeout_ = 30.0;
  double tf_timeout_ = 0.2;
  double max_pose_age_ = 5.0;  // s, an older map -> base_link is stale: no plan (0: any age)
  std::size_t stale_poses_ = 0;
  bool use_what_if_ = true;
  int what_if_seed_ = 1;
  std::vector<std::unique_ptr<PickerInput>> pickers_;  // in the order of the list
  std::map<std::string, PickerInput*> by_id_;
  std::unique_ptr<FleetBeliefs> beliefs_;
  ros::Subscriber registry_sub_;
  std::size_t beliefs_of_others_ = 0;  // beliefs of pickers not in the list (the stream carries the whole fleet)
  std::vector<ros::Subscriber> peer_subs_;
  std::map<std::string, PeerGoal> peer_goals_;
  StampGuard clock_guard_;  // jump-back detection only
  ros::Subscriber battery_sub_, call_goal_sub_, call_status_sub_;
  std::unique_ptr<nbs::TrayClock> tray_clock_;  // the pickers' call-due weights, from the dispatcher's calls
  std::size_t call_status_messages_ = 0;
  std::optional<picker_localisation::GoalNode> call_goal_;  // the dispatcher's goal while serving a call
  std::size_t call_goals_ = 0, call_goals_rejected_ = 0;
  ros::Publisher goal_pub_, goal_pose_pub_, marker_pub_;
  ros::ServiceServer candidates_srv_;
  ros::Timer timer_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  NodeDiagnostics diagnostics_;

  std::optional<nbs::PlanResult> last_plan_;
  ros::Time last_plan_stamp_;
  std::size_t plans_ = 0, failed_plans_ = 0, tf_failures_ = 0, fallback_plans_ = 0, peer_goals_rejected_ = 0;
  std::size_t markers_published_ = 0;
  std::string last_problem_, last_what_if_error_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
