#include "picker_localisation/ros/dispatcher_node.h"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <picker_localisation/GoalNode.h>
#include <sensor_msgs/NavSatFix.h>
#include <visualization_msgs/MarkerArray.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "picker_localisation/core/yaml_keys.h"
#include "picker_localisation/ros/map_conversions.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/param_yaml.h"

namespace picker_localisation {
namespace ros_adapter {

namespace {

// The typed call (service or topic) as the dispatcher reads every call.
dispatch::CallInput callInput(const picker_localisation::PickerCall& msg) {
  dispatch::CallInput in;
  in.picker_id = msg.picker_id;
  in.has_fix = msg.has_fix;
  in.latitude = msg.latitude;
  in.longitude = msg.longitude;
  in.row = msg.row;
  return in;
}

std_msgs::ColorRGBA colour(float r, float g, float b, float a = 1.0f) {
  std_msgs::ColorRGBA c;
  c.r = r, c.g = g, c.b = b, c.a = a;
  return c;
}

}  // namespace

// ---- node
// ---------------------------------------------------------------------------------------------------

DispatcherNode::DispatcherNode(ros::NodeHandle& nh, ros::NodeHandle& pnh)
    : nh_(nh), pnh_(pnh), tf_listener_(tf_buffer_) {
  const std::string name = ros::this_node::getName();
  if (!loadOptions(pnh_, options_)) return;
  try {
    if (options_.pickers_file.empty())
      throw std::runtime_error("~pickers_file is not set (config/pickers.yaml)");
    registry_ = core::PickerRegistry::load(options_.pickers_file);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", name.c_str(), e.what());
    return;
  }
  map_ = obtainMap(nh_, options_.map_source);
  if (!map_) return;
  // The datum places a call's fix on the map (as gnss_ingest does); without one, fixes are left out.
  try {
    if (useMapDatum(options_.datum_source, *map_))
      datum_ = std::make_unique<core::GeodeticDatum>(map_->datum()->config());
    else if (!options_.datum_file.empty())
      datum_ = std::make_unique<core::GeodeticDatum>(core::GeodeticDatum::load(options_.datum_file));
    else
      ROS_WARN("%s: no datum (the map has none and ~datum_file is not set): a call's fix is left out",
               name.c_str());
    if (options_.dispatcher.storage_node.empty())  // as the runner: the node outside the lanes nearest the
      options_.dispatcher.storage_node = dispatch::defaultStorageNode(*map_);  // lower-left corner
    dispatcher_ = std::make_unique<dispatch::CallDispatcher>(map_, options_.dispatcher, options_.robotIds());
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", name.c_str(), e.what());
    return;
  }
  map_follower_ = std::make_unique<MapFollower>(
      nh_, options_.map_source, map_,
      [this](std::shared_ptr<const topology::TopologicalMap> m, const topology::MapChange& change) {
        adoptMap(std::move(m), change);
      });

  beliefs_ = std::make_unique<FleetBeliefs>(
      nh_, options_.fleet.belief_topic,
      [this](const picker_localisation::PickerBelief& b) { beliefCallback(b); });
  beliefs_->follow(registry_.ids());
  registry_sub_ = followPickerList(nh_, options_.fleet, name.c_str(), [this](const core::PickerRegistry& r) {
    registry_ = r;
    beliefs_->follow(r.ids());
  });

  for (const std::string& robot : dispatcher_->robots()) {
    RobotIo& io = robots_[robot];
    const std::string ns = "/" + robot + "/";
    io.goal = nh_.advertise<picker_localisation::GoalNode>(ns + options_.goal_topic, 1, true);
    if (!options_.goal_pose_topic.empty())
      io.goal_pose = nh_.advertise<geometry_msgs::PoseStamped>(ns + options_.goal_pose_topic, 1, true);
    if (!options_.goal_node_topic.empty())
      io.goal_node = nh_.advertise<std_msgs::String>(ns + options_.goal_node_topic, 1, true);
    if (!options_.rfid_topic.empty())
      io.rfid = nh_.subscribe(ns + options_.rfid_topic, 100, &DispatcherNode::rfidCallback, this);
  }
  ros::NodeHandle& calls_nh = options_.calls_topic.rfind('~', 0) == 0 ? pnh_ : nh_;
  const std::string calls_topic =
      options_.calls_topic.rfind('~', 0) == 0 ? options_.calls_topic.substr(1) : options_.calls_topic;
  if (!calls_topic.empty())
    calls_sub_ = calls_nh.subscribe(calls_topic, 20, &DispatcherNode::callMessage, this);
  if (!options_.car_topic.empty())
    car_sub_ = nh_.subscribe(options_.car_topic, 20, &DispatcherNode::carMessage, this);
  if (!options_.observations_topic.empty()) {
    observations_sub_ =
        nh_.subscribe(options_.observations_topic, 200, &DispatcherNode::observationCallback, this);
    observation_pub_ = nh_.advertise<picker_localisation::Observation>(options_.observations_topic, 10);
  }
  if (!options_.calls_log.empty()) {
    const bool fresh = !std::ifstream(options_.calls_log).good();
    calls_log_.open(options_.calls_log, std::ios::app);
    if (!calls_log_)
      ROS_ERROR("%s: cannot write ~calls_log '%s'; calls are not logged", name.c_str(),
                options_.calls_log.c_str());
    else if (fresh)
      calls_log_ << dispatch::callLogHeader() << "\n" << std::flush;
  }
  status_pub_ = pnh_.advertise<picker_localisation::CallStatusArray>("status", 1, true);
  markers_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  call_srv_ = pnh_.advertiseService("call", &DispatcherNode::callService, this);
  cancel_srv_ = pnh_.advertiseService("cancel", &DispatcherNode::cancelService, this);
  get_calls_srv_ = pnh_.advertiseService("get_calls", &DispatcherNode::getCallsService, this);

  diagnostics_.setHardwareID("dispatcher");
  diagnostics_.add("dispatcher", this, &DispatcherNode::diagnose);
  for (const char* input : {"calls", "beliefs", "rfid", "people"}) diagnostics_.input(input);
  diagnostics_.start(nh_);
  timer_ = nh_.createTimer(ros::Duration(options_.update_period),
                           [this](const ros::TimerEvent&) { update(ros::Time::now()); });
  publishStatus(ros::Time::now());
  ROS_INFO("%s: %zu robots, %zu pickers, storage node '%s', calls on %s, %s and ~call", name.c_str(),
           dispatcher_->robots().size(), registry_.size(), options_.dispatcher.storage_node.c_str(),
           calls_sub_ ? calls_sub_.getTopic().c_str() : "(none)",
           car_sub_ ? car_sub_.getTopic().c_str() : "(no CAR topic)");
}

void DispatcherNode::refuse(const std::string& input, const std::string& why) {
  ++calls_refused_;
  last_refusal_ = input + ": " + why;
  ROS_ERROR_THROTTLE(2.0, "%s: %s refused: %s", ros::this_node::getName().c_str(), input.c_str(),
                     why.c_str());
}

bool DispatcherNode::takeCall(const dispatch::CallInput& input, const ros::Time& stamp, std::string* message,
                              std::uint64_t* call_id) {
  diagnostics_.tick("calls");
  const core::PickerConfig* picker = registry_.find(input.picker_id);
  if (!picker) {
    *message = "unknown picker '" + input.picker_id + "' (not in the pickers file or the tracker's list)";
    return false;
  }
  const ros::Time when = stamp.isZero() ? ros::Time::now() : stamp;
  const dispatch::CheckedCall checked =
      dispatch::checkCall(input, *map_, datum_.get(), options_.max_fix_distance);
  std::string error;
  const auto id = dispatcher_->call(input.picker_id, when.toSec(), &error);
  if (!id) {
    *message = error;
    return false;
  }
  ++calls_taken_;
  *call_id = *id;
  call_extras_[*id] = {input.row, checked.note};
  // The call's fix: the picker's GNSS topic, so gnss_ingest places it (a CAR app's only fix of the picker).
  if (checked.fix && options_.forward_fix && !picker->gnss_topic.empty()) {
    auto pub = fix_pubs_.find(picker->gnss_topic);
    if (pub == fix_pubs_.end())
      pub =
          fix_pubs_.emplace(picker->gnss_topic, nh_.advertise<sensor_msgs::NavSatFix>(picker->gnss_topic, 5))
              .first;
    sensor_msgs::NavSatFix fix;
    fix.header.stamp = when;
    fix.header.frame_id = "gps";
    fix.status.status = sensor_msgs::NavSatStatus::STATUS_FIX;
    fix.status.service = sensor_msgs::NavSatStatus::SERVICE_GPS;
    fix.latitude = input.latitude;
    fix.longitude = input.longitude;
    fix.altitude = std::numeric_limits<double>::quiet_NaN();
    fix.position_covariance_type = sensor_msgs::NavSatFix::COVARIANCE_TYPE_UNKNOWN;
    pub->second.publish(fix);
  }
  // The reported row: evidence for the picker's filter (a mistyped row only down-weights, never removes).
  if (checked.row_lane != topology::kNoLane && observation_pub_ && options_.row_evidence_floor < 1.0) {
    const core::Observation obs = dispatch::reportedRowObservation(*map_, checked.row_lane, input.picker_id,
                                                                   when.toSec(), options_.row_evidence_floor);
    observation_pub_.publish(toMsg(obs, *map_, options_.map_frame));
  }
  *message = checked.note.empty() ? "call " + std::to_string(*id) + " queued"
                                  : "call " + std::to_string(*id) + " queued; " + checked.note;
  if (!checked.note.empty())
    ROS_WARN("%s: call %lu of %s: %s", ros::this_node::getName().c_str(), static_cast<unsigned long>(*id),
             input.picker_id.c_str(), checked.note.c_str());
  ROS_INFO("%s: call %lu of %s", ros::this_node::getName().c_str(), static_cast<unsigned long>(*id),
           input.picker_id.c_str());
  publishStatus(ros::Time::now());  // queued, then at once a free robot goes
  update(ros::Time::now());
  return true;
}

bool DispatcherNode::takeCancel(std::uint64_t call_id, const std::string& picker_id, std::string* message) {
  if (call_id == 0) {
    for (const dispatch::Call& c : dispatcher_->calls())
      if (c.picker_id == picker_id && c.open()) call_id = c.id;
    if (call_id == 0) {
      *message = "picker '" + picker_id + "' has no open call";
      return false;
    }
  }
  const dispatch::Call* before = dispatcher_->find(call_id);
  const std::string robot = before ? before->robot_id : "";
  if (!dispatcher_->cancel(call_id, ros::Time::now().toSec(), message)) return false;
  ++cancels_;
  if (!robot.empty()) freeRobot(robot, ros::Time::now());
  *message = "call " + std::to_string(call_id) + " cancelled";
  ROS_INFO("%s: %s", ros::this_node::getName().c_str(), message->c_str());
  publishStatus(ros::Time::now());
  return true;
}

bool DispatcherNode::callService(picker_localisation::CallRobot::Request& req,
                                 picker_localisation::CallRobot::Response& res) {
  res.success = takeCall(callInput(req.call), req.call.header.stamp, &res.message, &res.call_id);
  if (!res.success) refuse("~call", res.message);
  return true;
}

bool DispatcherNode::cancelService(picker_localisation::CancelCall::Request& req,
                                   picker_localisation::CancelCall::Response& res) {
  res.success = takeCancel(req.call_id, req.picker_id, &res.message);
  if (!res.success) refuse("~cancel", res.message);
  return true;
}

bool DispatcherNode::getCallsService(picker_localisation::GetCalls::Request& req,
                                     picker_localisation::GetCalls::Response& res) {
  for (const dispatch::Call& c : dispatcher_->calls())
    if (req.include_closed || c.open()) res.calls.push_back(statusOf(c));
  return true;
}

void DispatcherNode::callMessage(const picker_localisation::PickerCall::ConstPtr& msg) {
  std::string message;
  std::uint64_t id = 0;
  if (!takeCall(callInput(*msg), msg->header.stamp, &message, &id))
    refuse("call on " + calls_sub_.getTopic(), message);
}

void DispatcherNode::carMessage(const std_msgs::String::ConstPtr& msg) {
  std::string error;
  const auto in = dispatch::parseCarMessage(msg->data, &error);
  if (!in) {
    diagnostics_.tick("calls");
    refuse("CAR message on " + car_sub_.getTopic(), error);
    return;
  }
  std::string message;
  std::uint64_t id = 0;
  if (in->cancel) {
    if (!takeCancel(0, in->picker_id, &message)) refuse("CAR cancel on " + car_sub_.getTopic(), message);
    return;
  }
  // The CAR app's JSON carries no stamp: the call is as of its arrival.
  if (!takeCall(*in, ros::Time(), &message, &id)) refuse("CAR call on " + car_sub_.getTopic(), message);
}

void DispatcherNode::beliefCallback(const picker_localisation::PickerBelief& msg) {
  diagnostics_.tick("beliefs");
  if (msg.nodes.empty()) return;  // waiting for its first observation
  const BeliefSupport support = beliefSupport(msg, *map_);
  if (!dispatcher_->setBelief(msg.picker_id, support.nodes, support.masses)) {
    ++beliefs_rejected_;
    ROS_WARN_THROTTLE(10.0, "%s: belief of %s not used (no node of this map with a valid mass)",
                      ros::this_node::getName().c_str(), msg.picker_id.c_str());
  }
}

void DispatcherNode::rfidCallback(const picker_localisation::RfidReading::ConstPtr& msg) {
  diagnostics_.tick("rfid");
  const auto picker = registry_.pickerForRfidTag(msg->tag_id);
  if (!picker || robots_.find(msg->robot_id) == robots_.end()) return;
  if (dispatcher_->rfidRead(msg->robot_id, *picker, msg->header.stamp.toSec(), msg->rssi)) {
    ++arrivals_;
    ROS_INFO("%s: %s read %s's tag at %.0f dBm: arrived", ros::this_node::getName().c_str(),
             msg->robot_id.c_str(), picker->c_str(), msg->rssi);
    publishStatus(ros::Time::now());
  }
}

void DispatcherNode::observationCallback(const picker_localisation::Observation::ConstPtr& msg) {
  // Identified people seen by a robot's own sensor (gnss_ingest's association); the node's own reported-row
  // observations and GNSS are not sightings.
  if (!msg->identifying || msg->robot_id.empty() || robots_.find(msg->robot_id) == robots_.end()) return;
  if (std::find(options_.arrival_sensors.begin(), options_.arrival_sensors.end(), msg->sensor) ==
      options_.arrival_sensors.end())
    return;
  diagnostics_.tick("people");
  if (!dispatcher_->servedBy(msg->robot_id)) return;
  if (!std::isfinite(msg->position.x) || !std::isfinite(msg->position.y)) return;
  const auto robot = robotPosition(msg->robot_id);
  if (!robot) return;
  const double d = (Eigen::Vector2d(msg->position.x, msg->position.y) - *robot).norm();
  // The probability the association named the person at (none given: a sure identity).
  double probability = 1.0;
  for (std::size_t k = 0; k < msg->candidate_pickers.size() && k < msg->candidate_probabilities.size(); ++k)
    if (msg->candidate_pickers[k] == msg->picker_id) probability = msg->candidate_probabilities[k];
  if (dispatcher_->lidarPerson(msg->robot_id, msg->picker_id, msg->header.stamp.toSec(), d, probability)) {
    ++arrivals_;
    ROS_INFO("%s: %s sees %s %.1f m away (%s): arrived", ros::this_node::getName().c_str(),
             msg->robot_id.c_str(), msg->picker_id.c_str(), d, msg->sensor.c_str());
    publishStatus(ros::Time::now());
  }
}

std::optional<Eigen::Vector2d> DispatcherNode::robotPosition(const std::string& robot) {
  try {
    const geometry_msgs::TransformStamped t =
        tf_buffer_.lookupTransform(options_.map_frame, options_.baseFrame(robot), ros::Time(0));
    // A zero stamp is a static chain (a robot fixed in place): never stale.
    if (options_.max_pose_age > 0.0 && !t.header.stamp.isZero() &&
        (ros::Time::now() - t.header.stamp).toSec() > options_.max_pose_age) {
      ++pose_failures_;
      ROS_WARN_THROTTLE(10.0, "%s: the pose of %s is %.1f s old (more than ~max_pose_age)",
                        ros::this_node::getName().c_str(), robot.c_str(),
                        (ros::Time::now() - t.header.stamp).toSec());
      return std::nullopt;
    }
    return Eigen::Vector2d(t.transform.translation.x, t.transform.translation.y);
  } catch (const tf2::TransformException& e) {
    ++pose_failures_;
    ROS_WARN_THROTTLE(10.0, "%s: no pose of %s: %s", ros::this_node::getName().c_str(), robot.c_str(),
                      e.what());
    return std::nullopt;
  }
}

void DispatcherNode::update(const ros::Time& now) {
  if (!dispatcher_) return;
  for (const std::string& robot : dispatcher_->robots())
    if (const auto p = robotPosition(robot)) {
      robot_xy_[robot] = *p;
      dispatcher_->setRobotNode(robot, map_->nearestNode(*p));
    }
  const std::vector<dispatch::Goal> goals = dispatcher_->update(now.toSec());
  for (const dispatch::Goal& g : goals) sendGoal(g, now);
  // A call that ended frees its robot: its planner positions it again.
  for (auto& [robot, io] : robots_) {
    if (io.serving == 0) continue;
    const dispatch::Call* c = dispatcher_->find(io.serving);
    if (!c || !c->open() || c->robot_id != robot) freeRobot(robot, now);
  }
  publishStatus(now);
}

void DispatcherNode::sendGoal(const dispatch::Goal& goal, const ros::Time& stamp) {
  auto io = robots_.find(goal.robot_id);
  if (io == robots_.end() || goal.node >= map_->numNodes()) return;
  const dispatch::Call* call = dispatcher_->find(goal.call_id);
  picker_localisation::GoalNode msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = options_.map_frame;
  msg.robot_id = goal.robot_id;
  msg.node = map_->node(goal.node).name;
  msg.pose = nodePose(map_->node(goal.node));
  msg.utility = 1.0;
  msg.policy = "call";
  msg.target_picker = call && goal.state != dispatch::CallState::kToStorage ? call->picker_id : "";
  io->second.goal.publish(msg);
  if (io->second.goal_pose) {
    geometry_msgs::PoseStamped pose;
    pose.header = msg.header;
    pose.pose = msg.pose;
    io->second.goal_pose.publish(pose);
  }
  if (io->second.goal_node) {
    std_msgs::String node;
    node.data = msg.node;
    io->second.goal_node.publish(node);
  }
  io->second.serving = goal.call_id;
  ++goals_sent_;
}

void DispatcherNode::freeRobot(const std::string& robot, const ros::Time& stamp) {
  auto io = robots_.find(robot);
  if (io == robots_.end()) return;
  io->second.serving = 0;
  // An empty node and a NaN pose: no call goal, the robot's planner takes over (without one it stays).
  picker_localisation::GoalNode msg;
  msg.pose.position.x = msg.pose.position.y = msg.pose.position.z = std::numeric_limits<double>::quiet_NaN();
  msg.header.stamp = stamp;
  msg.header.frame_id = options_.map_frame;
  msg.robot_id = robot;
  msg.policy = "call";
  io->second.goal.publish(msg);
}

picker_localisation::CallStatus DispatcherNode::statusOf(const dispatch::Call& c) const {
  picker_localisation::CallStatus s;
  s.call_id = c.id;
  s.picker_id = c.picker_id;
  s.state = dispatch::toString(c.state);
  s.robot_id = c.robot_id;
  if (c.open() && c.target < map_->numNodes()) s.target_node = map_->node(c.target).name;
  s.called = rosStamp(c.stamp);
  s.assigned = rosStamp(c.assigned_at);
  s.arrived = rosStamp(c.arrived_at);
  s.done = rosStamp(c.done_at);
  const auto extra = call_extras_.find(c.id);
  if (extra != call_extras_.end()) s.row = extra->second.first, s.note = extra->second.second;
  if (c.state == dispatch::CallState::kQueued && s.note.empty())
    s.note = dispatcher_->target(c.picker_id) == topology::kInvalidNode ? "waiting for the picker's belief"
                                                                        : "waiting for a free robot";
  return s;
}

DispatcherNode::~DispatcherNode() {
  if (!calls_log_ || !dispatcher_) return;
  logClosedCalls();
  for (const dispatch::Call& c : dispatcher_->calls())
    if (c.open()) calls_log_ << dispatch::callLogLine(c, *map_) << "\n";
  calls_log_.flush();
}

void DispatcherNode::logClosedCalls() {
  if (!calls_log_.is_open() || !calls_log_) return;
  for (const dispatch::Call& c : dispatcher_->calls())
    if (!c.open() && logged_calls_.insert(c.id).second) calls_log_ << dispatch::callLogLine(c, *map_) << "\n";
  calls_log_.flush();
}

void DispatcherNode::publishStatus(const ros::Time& stamp) {
  logClosedCalls();
  picker_localisation::CallStatusArray msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = options_.map_frame;
  const auto& calls = dispatcher_->calls();
  std::size_t closed_seen = 0;
  for (auto it = calls.rbegin(); it != calls.rend(); ++it) {
    if (!it->open() && closed_seen++ >= static_cast<std::size_t>(options_.closed_calls_kept)) continue;
    msg.calls.push_back(statusOf(*it));
  }
  std::reverse(msg.calls.begin(), msg.calls.end());
  status_pub_.publish(msg);
  publishMarkers(stamp);
}

void DispatcherNode::publishMarkers(const ros::Time& stamp) {
  // Open calls: a line from the serving robot to its target, the target node as a ring, a label "picker <-
  // robot (state)" above the target; a queued call is a label at the picker's most likely node.
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  array.markers.push_back(clear);
  int id = 0;
  for (const dispatch::Call& c : dispatcher_->calls()) {
    if (!c.open()) continue;
    const topology::NodeIndex at = c.target < map_->numNodes() ? c.target : dispatcher_->target(c.picker_id);
    if (at >= map_->numNodes()) continue;
    const Eigen::Vector3d p = map_->node(at).position;
    visualization_msgs::Marker label;
    label.header.stamp = stamp;
    label.header.frame_id = options_.map_frame;
    label.ns = "calls";
    label.id = id++;
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    label.pose.position.x = p.x();
    label.pose.position.y = p.y();
    label.pose.position.z = p.z() + 2.5;
    label.pose.orientation.w = 1.0;
    label.scale.z = 0.8;
    // Orange: a call served (red while queued), apart from the pale lanes and the cyan-magenta beliefs.
    label.color = c.robot_id.empty() ? colour(1.0f, 0.15f, 0.15f) : colour(1.0f, 0.55f, 0.0f);
    label.text =
        c.picker_id + (c.robot_id.empty() ? "" : " <- " + c.robot_id) + " (" + toString(c.state) + ")";
    array.markers.push_back(label);
    visualization_msgs::Marker ring = label;
    ring.ns = "call_targets";
    ring.id = id++;
    ring.type = visualization_msgs::Marker::CYLINDER;
    ring.pose.position.z = p.z() + 0.05;
    ring.scale.x = ring.scale.y = 1.6;
    ring.scale.z = 0.1;
    ring.color.a = 0.6f;
    ring.text.clear();
    array.markers.push_back(ring);
    if (c.robot_id.empty()) continue;
    const auto robot = robot_xy_.find(c.robot_id);  // where the last update placed it
    if (robot == robot_xy_.end()) continue;
    visualization_msgs::Marker line = ring;
    line.ns = "call_routes";
    line.id = id++;
    line.type = visualization_msgs::Marker::LINE_STRIP;
    line.pose = geometry_msgs::Pose();
    line.pose.orientation.w = 1.0;
    line.scale.x = 0.25;
    line.color.a = 0.9f;
    geometry_msgs::Point a, b;
    a.x = robot->second.x(), a.y = robot->second.y(), a.z = 0.5;
    b.x = p.x(), b.y = p.y(), b.z = 0.5;
    line.points = {a, b};
    array.markers.push_back(line);
  }
  markers_pub_.publish(array);
}

void DispatcherNode::adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                              const topology::MapChange& change) {
  try {
    dispatcher_->adoptMap(map, change);
    map_ = std::move(map);
    if (change.datum_changed && useMapDatum(options_.datum_source, *map_))
      datum_ = std::make_unique<core::GeodeticDatum>(map_->datum()->config());
  } catch (const std::exception& e) {
    ROS_ERROR("%s: the new map is not used, dispatching on the current one: %s",
              ros::this_node::getName().c_str(), e.what());
  }
}

void DispatcherNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::size_t open = 0, queued = 0;
  for (const dispatch::Call& c : dispatcher_->calls()) {
    open += c.open() ? 1 : 0;
    queued += c.state == dispatch::CallState::kQueued ? 1 : 0;
  }
  if (calls_refused_ > 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "calls refused; last: " + last_refusal_);
  else if (pose_failures_ > 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "some robot poses missing or stale");
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "serving");
  stat.add("open calls", open);
  stat.add("queued calls", queued);
  stat.add("calls taken", calls_taken_);
  stat.add("calls refused", calls_refused_);
  stat.add("cancelled", cancels_);
  stat.add("arrivals", arrivals_);
  stat.add("goals sent", goals_sent_);
  stat.add("beliefs rejected", beliefs_rejected_);
  stat.add("robot pose failures", pose_failures_);
}

}  // namespace ros_adapter
}  // namespace picker_localisation
