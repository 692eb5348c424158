// dispatcher: answers the pickers' calls for the whole fleet (one node per farm) with the ROS-free
// dispatch::CallDispatcher the offline runner drives too. Parameters, topics and services:
// docs/readme/dispatch.md; defaults config/dispatcher.yaml.
//
// In:  ~call (CallRobot), ~calls (PickerCall), ~car_topic (std_msgs/String, the LCAS CAR app's JSON),
// ~cancel,
//      the trackers' beliefs (/pickers/beliefs), each robot's pose (tf map -> <robot>/base_link), arrival
//      sensing: each robot's tag reads (/<robot>/rfid) and identified people (/observations, from
//      gnss_ingest's association).
// Out: per robot /<robot>/<goal_topic> (GoalNode, policy "call"; an empty node frees the robot: nbs_planner
//      forwards a call goal as the robot's goal and plans again once freed), /<robot>/<goal_pose_topic>
//      (PoseStamped), /<robot>/<goal_node_topic> (std_msgs/String, the node name LCAS topological navigation
//      takes); ~status (CallStatusArray, latched); ~markers (rviz); the reported row as an observation for
//      the picker's filter; the call's fix on the picker's GNSS topic; diagnostics.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <picker_localisation/CallRobot.h>
#include <picker_localisation/CallStatusArray.h>
#include <picker_localisation/CancelCall.h>
#include <picker_localisation/GetCalls.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/PickerCall.h>
#include <picker_localisation/RfidReading.h>
#include <std_msgs/String.h>

#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/dispatch/call_dispatcher.h"
#include "picker_localisation/dispatch/call_input.h"
#include "picker_localisation/dispatch/dispatcher_node_options.h"
#include "picker_localisation/ros/fleet_topics.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/node_diagnostics.h"

namespace picker_localisation {
namespace ros_adapter {

class DispatcherNode {
 public:
  DispatcherNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  ~DispatcherNode();  // the calls still open go to ~calls_log
  bool ok() const { return static_cast<bool>(dispatcher_); }
  // One dispatcher update at ROS time `now` (the timer calls it). Public for tests.
  void update(const ros::Time& now);

 private:
  struct RobotIo {
    ros::Publisher goal, goal_pose, goal_node;
    ros::Subscriber rfid;
    std::uint64_t serving = 0;  // the call whose goal was sent last (0: free)
  };
  // A call from any input; false and *message when refused.
  bool takeCall(const dispatch::CallInput& input, const ros::Time& stamp, std::string* message,
                std::uint64_t* call_id);
  bool takeCancel(std::uint64_t call_id, const std::string& picker_id, std::string* message);
  bool callService(picker_localisation::CallRobot::Request& req,
                   picker_localisation::CallRobot::Response& res);
  bool cancelService(picker_localisation::CancelCall::Request& req,
                     picker_localisation::CancelCall::Response& res);
  bool getCallsService(picker_localisation::GetCalls::Request& req,
                       picker_localisation::GetCalls::Response& res);
  void callMessage(const picker_localisation::PickerCall::ConstPtr& msg);
  void carMessage(const std_msgs::String::ConstPtr& msg);
  void beliefCallback(const picker_localisation::PickerBelief& msg);
  void rfidCallback(const picker_localisation::RfidReading::ConstPtr& msg);
  void observationCallback(const picker_localisation::Observation::ConstPtr& msg);
  std::optional<Eigen::Vector2d> robotPosition(const std::string& robot);
  void sendGoal(const dispatch::Goal& goal, const ros::Time& stamp);
  void freeRobot(const std::string& robot, const ros::Time& stamp);
  picker_localisation::CallStatus statusOf(const dispatch::Call& call) const;
  void publishStatus(const ros::Time& stamp);
  void logClosedCalls();  // ~calls_log: every call closed since the last time, once
  void publishMarkers(const ros::Time& stamp);
  void adoptMap(std::shared_ptr<const topology::TopologicalMap> map, const topology::MapChange& change);
  void refuse(const std::string& input, const std::string& why);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::NodeHandle nh_, pnh_;
  dispatch::DispatcherNodeOptions options_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<dispatch::CallDispatcher> dispatcher_;
  std::unique_ptr<core::GeodeticDatum> datum_;
  core::PickerRegistry registry_;
  std::unique_ptr<MapFollower> map_follower_;
  std::unique_ptr<FleetBeliefs> beliefs_;
  ros::Subscriber registry_sub_, calls_sub_, car_sub_, observations_sub_;
  ros::Publisher status_pub_, markers_pub_, observation_pub_;
  std::map<std::string, ros::Publisher> fix_pubs_;  // by GNSS topic
  ros::ServiceServer call_srv_, cancel_srv_, get_calls_srv_;
  std::map<std::string, RobotIo> robots_;
  std::map<std::string, Eigen::Vector2d> robot_xy_;  // each robot's position at the last update (map frame)
  std::map<std::uint64_t, std::pair<std::string, std::string>> call_extras_;  // call id -> (row, note)
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  ros::Timer timer_;
  NodeDiagnostics diagnostics_;
  std::size_t calls_taken_ = 0, calls_refused_ = 0, cancels_ = 0, arrivals_ = 0, beliefs_rejected_ = 0,
              pose_failures_ = 0, goals_sent_ = 0;
  std::string last_refusal_;
  std::ofstream calls_log_;
  std::set<std::uint64_t> logged_calls_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
