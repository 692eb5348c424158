#include "picker_localisation/ros/nbs_planner_node.h"
#include "picker_localisation/nbs/nbs_planner_node_options.h"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/ros/map_conversions.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/ros/what_if_belief_source.h"

namespace picker_localisation {
namespace ros_adapter {

namespace {

std_msgs::ColorRGBA utilityColour(double u) {
  // red (0) -> yellow (0.5) -> green (1)
  std_msgs::ColorRGBA c;
  u = std::clamp(u, 0.0, 1.0);
  c.r = static_cast<float>(u < 0.5 ? 1.0 : 2.0 * (1.0 - u));
  c.g = static_cast<float>(u < 0.5 ? 2.0 * u : 1.0);
  c.b = 0.1f;
  c.a = 0.8f;
  return c;
}

}  // namespace

NbsPlannerNode::NbsPlannerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh)
    : nh_(nh), pnh_(pnh), tf_listener_(tf_buffer_) {
  const std::string name = ros::this_node::getName();
  nbs::NbsPlannerNodeOptions o;
  if (!loadOptions(pnh_, o)) return;
  const nbs::PlannerConfig& config = o.planner;
  robot_id_ = o.robotId(ros::this_node::getNamespace());
  map_frame_ = o.common.map_frame;
  tf_timeout_ = o.common.tf_timeout;
  base_frame_ = o.baseFrame(robot_id_);
  battery_level_ = o.battery_level;
  claim_timeout_ = o.claim_timeout;
  max_pose_age_ = o.max_pose_age;
  use_what_if_ = o.use_what_if;
  what_if_seed_ = o.what_if_seed;
  const double period = o.planning_period;
  core::PickerRegistry registry;
  try {
    if (o.fleet.pickers_file.empty())
      throw std::runtime_error("~pickers_file is not set (config/pickers.yaml)");
    registry = core::PickerRegistry::load(o.fleet.pickers_file);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", name.c_str(), e.what());
    return;
  }
  map_ = obtainMap(nh_, o.common);
  if (!map_) return;
  try {
    planner_ = std::make_unique<nbs::NextBestSensePlanner>(map_, config);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", name.c_str(), e.what());
    return;
  }
  // A map edited at run time: the planner is built again on it (same configuration); the last plan, which
  // names nodes of the old map, is forgotten. Beliefs and goals are kept by node name.
  map_follower_ = std::make_unique<MapFollower>(
      nh_, o.common, map_,
      [this](std::shared_ptr<const topology::TopologicalMap> m, const topology::MapChange&) {
        try {
          auto rebuilt = std::make_unique<nbs::NextBestSensePlanner>(m, planner_->config());
          planner_ = std::move(rebuilt);
          map_ = std::move(m);
          last_plan_.reset();
        } catch (const std::exception& e) {
          ROS_ERROR("%s: the new map is not used, planning on the current one: %s",
                    ros::this_node::getName().c_str(), e.what());
        }
      });

  // Inputs: the trackers' beliefs (never ground truth), the other robots' goals, the battery.
  beliefs_ = std::make_unique<FleetBeliefs>(
      nh_, o.fleet.belief_topic, [this](const picker_localisation::PickerBelief& b) { beliefCallback(b); });
  applyPickerList(registry.ids());
  registry_sub_ = followPickerList(nh_, o.fleet, name.c_str(),
                                   [this](const core::PickerRegistry& r) { applyPickerList(r.ids()); });
  for (const std::string& other : o.robotIds())
    if (other != robot_id_)
      peer_subs_.push_back(nh_.subscribe("/" + other + "/goal", 5, &NbsPlannerNode::peerGoalCallback, this));
  if (!o.battery_topic.empty())
    battery_sub_ = nh_.subscribe(o.battery_topic, 5, &NbsPlannerNode::batteryCallback, this);

  goal_pub_ = nh_.advertise<picker_localisation::GoalNode>("goal", 1, true);
  // The same goal for navigation stacks that take a pose (move_base_simple/goal style), latched.
  if (!o.goal_pose_topic.empty())
    goal_pose_pub_ = nh_.advertise<geometry_msgs::PoseStamped>(o.goal_pose_topic, 1, true);
  marker_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("nbs_candidates", 1, true);
  // The dispatcher's goal for this robot while it serves a call (dispatcher ~goal_topic; "" none).
  if (!o.call_goal_topic.empty())
    call_goal_sub_ = nh_.subscribe(o.call_goal_topic, 5, &NbsPlannerNode::callGoalCallback, this);
  // The dispatcher's calls: which pickers are about to call (call_due_weight).
  tray_clock_ = std::make_unique<nbs::TrayClock>(config.call_due_weight, config.tray_time_mean);
  if (!o.call_status_topic.empty() && config.call_due_weight > 0.0)
    call_status_sub_ = nh_.subscribe(o.call_status_topic, 5, &NbsPlannerNode::callStatusCallback, this);
  candidates_srv_ = nh_.advertiseService("get_candidates", &NbsPlannerNode::getCandidates, this);
  diagnostics_.setHardwareID(robot_id_);
  diagnostics_.add("nbs_planner", this, &NbsPlannerNode::diagnose);
  timer_ = nh_.createTimer(ros::Duration(period), [this](const ros::TimerEvent&) { planOnce(); });
  diagnostics_.input("beliefs");
  diagnostics_.start(nh_);
  ROS_INFO("%s: robot %s, policy %s, %zu pickers (beliefs from %s), %zu other robots, planning every %.1f s",
           name.c_str(), robot_id_.c_str(), nbs::toString(config.policy), pickers_.size(),
           beliefs_->topic().c_str(), peer_subs_.size(), period);
  ok_ = true;
}

void NbsPlannerNode::applyPickerList(const std::vector<std::string>& ids) {
  // The list is the truth: a picker that left takes its belief and what-if client with it.
  std::vector<std::unique_ptr<PickerInput>> next;
  for (const std::string& id : ids) {
    auto it = std::find_if(pickers_.begin(), pickers_.end(), [&](const auto& in) { return in && in->id == id; });
    if (it != pickers_.end()) {
      next.push_back(std::move(*it));
      continue;
    }
    auto in = std::make_unique<PickerInput>();
    in->id = id;
    if (use_what_if_ && planner_->config().policy == nbs::Policy::kNextBestSense)
      in->what_if = nh_.serviceClient<picker_localisation::WhatIf>("/pickers/" + id + "/what_if", true);
    next.push_back(std::move(in));
  }
  pickers_ = std::move(next);
  by_id_.clear();
  for (auto& in : pickers_) by_id_[in->id] = in.get();
  beliefs_->follow(ids);
}

void NbsPlannerNode::beliefCallback(const picker_localisation::PickerBelief& msg) {
  diagnostics_.tick("beliefs");
  const auto found = by_id_.find(msg.picker_id);
  if (found == by_id_.end()) {
    ++beliefs_of_others_;
    return;
  }
  PickerInput& in = *found->second;
  if (msg.nodes.empty() && msg.masses.empty()) {
    // A new or reset picker's belief, "waiting for the first observation": nothing to plan on, nothing wrong.
    in.belief.reset();
    return;
  }
  std::size_t rejected = 0;
  const nbs::NodeMasses masses = massesFromBelief(msg, *map_, &rejected);
  if (masses.empty()) {
    ++in.rejected;
    ROS_WARN_THROTTLE(10.0, "%s: rejected a belief of %s (no node of this map with a valid mass)",
                      ros::this_node::getName().c_str(), in.id.c_str());
    return;
  }
  if (rejected > 0) ++in.rejected;
  ++in.received;
  in.belief = msg;
}

void NbsPlannerNode::peerGoalCallback(const picker_localisation::GoalNode::ConstPtr& msg) {
  if (msg->robot_id.empty() || msg->robot_id == robot_id_ ||
      (!msg->node.empty() && !map_->index(msg->node))) {
    ++peer_goals_rejected_;
    ROS_WARN_THROTTLE(10.0, "%s: ignored a goal of robot '%s' (node '%s' not in the map or bad robot id)",
                      ros::this_node::getName().c_str(), msg->robot_id.c_str(), msg->node.c_str());
    return;
  }
  peer_goals_[msg->robot_id] = {*msg, ros::Time::now()};
}

void NbsPlannerNode::batteryCallback(const sensor_msgs::BatteryState::ConstPtr& msg) {
  if (!std::isfinite(msg->percentage) || msg->percentage < 0.0f || msg->percentage > 1.0f) {
    ROS_WARN_THROTTLE(10.0, "%s: battery percentage %f is not in [0, 1]; keeping %.2f",
                      ros::this_node::getName().c_str(), msg->percentage, battery_level_);
    return;
  }
  battery_level_ = msg->percentage;
}

std::optional<topology::NodeIndex> NbsPlannerNode::robotNode() {
  try {
    const geometry_msgs::TransformStamped t =
        tf_buffer_.lookupTransform(map_frame_, base_frame_, ros::Time(0), ros::Duration(tf_timeout_));
    const Eigen::Vector2d p(t.transform.translation.x, t.transform.translation.y);
    if (!p.allFinite()) throw tf2::TransformException("non-finite robot position");
    // When the robot's localisation stops, tf keeps serving its last pose: planning from it would send the
    // robot from where it was. A zero stamp is a static chain (a fixed robot): never stale.
    const double age = secondsBetween(t.header.stamp, ros::Time::now());
    if (max_pose_age_ > 0.0 && !t.header.stamp.isZero() && age > max_pose_age_) {
      ++stale_poses_;
      char why[128];
      std::snprintf(why, sizeof(why), "robot pose %.1f s old (> max_pose_age %.1f s)", age, max_pose_age_);
      last_problem_ = why;
      ROS_WARN_THROTTLE(10.0, "%s: the robot pose %s -> %s is %.1f s old (> ~max_pose_age %.1f s): not planning",
                        ros::this_node::getName().c_str(), map_frame_.c_str(), base_frame_.c_str(), age,
                        max_pose_age_);
      return std::nullopt;
    }
    return map_->nearestNode(p);
  } catch (const std::exception& e) {  // tf2::TransformException, and ros::Duration's range error
    ++tf_failures_;
    last_problem_ = std::string("no robot pose: ") + e.what();
    ROS_WARN_THROTTLE(10.0, "%s: no pose %s -> %s: %s", ros::this_node::getName().c_str(), map_frame_.c_str(),
                      base_frame_.c_str(), e.what());
    return std::nullopt;
  }
}

void NbsPlannerNode::callGoalCallback(const picker_localisation::GoalNode::ConstPtr& msg) {
  if (msg->node.empty()) {  // the call ended: the robot is the planner's again
    if (call_goal_) ROS_INFO("%s: call goal released, planning again", ros::this_node::getName().c_str());
    call_goal_.reset();
    planOnce();
    return;
  }
  if (!map_->index(msg->node)) {
    ++call_goals_rejected_;
    ROS_WARN_THROTTLE(10.0, "%s: call goal node '%s' is not on the map; ignored",
                      ros::this_node::getName().c_str(), msg->node.c_str());
    return;
  }
  call_goal_ = *msg;
  ++call_goals_;
  forwardCallGoal(ros::Time::now());
}

void NbsPlannerNode::callStatusCallback(const picker_localisation::CallStatusArray::ConstPtr& msg) {
  ++call_status_messages_;
  for (const picker_localisation::CallStatus& c : msg->calls) {
    const bool open = c.state != "done" && c.state != "cancelled";
    const double arrived = c.arrived.isZero() ? std::numeric_limits<double>::quiet_NaN() : c.arrived.toSec();
    tray_clock_->observeCall(c.picker_id, c.called.toSec(), arrived, open);
  }
}

void NbsPlannerNode::forwardCallGoal(const ros::Time& stamp) {
  // The dispatcher's goal is the robot's goal (one goal topic per robot); re-sent each planning period with a
  // fresh stamp, so the other planners keep seeing the claim on the called picker.
  picker_localisation::GoalNode g = *call_goal_;
  g.header.stamp = stamp;
  g.robot_id = robot_id_;
  publishGoal(g);
}

void NbsPlannerNode::publishGoal(const picker_localisation::GoalNode& g) {
  goal_pub_.publish(g);
  if (goal_pose_pub_) {  // the same goal for navigation stacks that take a pose
    geometry_msgs::PoseStamped p;
    p.header = g.header;
    p.pose = g.pose;
    goal_pose_pub_.publish(p);
  }
}

void NbsPlannerNode::planOnce() {
  if (call_goal_) {  // serving a call: the dispatcher decides where the robot goes
    forwardCallGoal(ros::Time::now());
    return;
  }
  if (clock_guard_.clockJumpedBack()) {
    // Peer goals stamped in the old time would never age out (claim_timeout counts forward).
    ROS_WARN("nbs_planner: the clock jumped back: peer goals and the last plan forgotten");
    peer_goals_.clear();
    last_plan_.reset();
    tray_clock_->reset();
  }
  const ros::Time stamp = ros::Time::now();
  const auto robot = robotNode();
  if (!robot) {
    ++failed_plans_;
    return;
  }
  std::vector<std::unique_ptr<WhatIfBeliefSource>> sources;
  std::vector<nbs::BeliefSource*> pointers;
  for (auto& in : pickers_) {
    if (!in->belief) continue;
    ros::ServiceClient* client = nullptr;
    if (use_what_if_ && planner_->config().policy == nbs::Policy::kNextBestSense) {
      if (!in->what_if.isValid())  // persistent connections do not reconnect by themselves
        in->what_if = nh_.serviceClient<picker_localisation::WhatIf>("/pickers/" + in->id + "/what_if", true);
      client = &in->what_if;
    }
    sources.push_back(std::make_unique<WhatIfBeliefSource>(
        in->id, map_, *in->belief, client, static_cast<std::uint32_t>(what_if_seed_), map_frame_));
    pointers.push_back(sources.back().get());
  }
  std::vector<nbs::Claim> goals;
  for (const auto& [id, g] : peer_goals_) {
    if ((stamp - g.received).toSec() > claim_timeout_ || g.msg.node.empty()) continue;  // stale
    const auto node = map_->index(g.msg.node);
    if (!node) continue;  // a node the map lost in an edit since the goal came
    goals.push_back({id, *node, g.msg.target_picker});
  }
  const nbs::PickerWeights weights = tray_clock_->weights(pointers, stamp.toSec());  // 1 with weight 0
  nbs::PlanResult plan =
      planner_->plan(*robot, battery_level_, pointers, nbs::claimsFor(robot_id_, goals), weights);
  bool fallback = false;
  for (const auto& s : sources)
    if (s->usedFallback()) {
      fallback = true;
      last_what_if_error_ = s->lastError();
    }
  if (!fallback) last_what_if_error_.clear();  // a what-if problem of a picker since removed is not kept
  if (fallback) {
    ++fallback_plans_;
    ROS_WARN_THROTTLE(30.0, "%s: %s; planned with the published belief held still (no prediction)",
                      ros::this_node::getName().c_str(), last_what_if_error_.c_str());
  }
  ++plans_;
  if (!plan.ok()) {
    ++failed_plans_;
    last_problem_ = plan.problem;
    ROS_WARN_THROTTLE(10.0, "%s: no goal: %s", ros::this_node::getName().c_str(), plan.problem.c_str());
  } else {
    last_problem_.clear();
  }
  last_plan_ = std::move(plan);
  last_plan_stamp_ = stamp;
  publish(*last_plan_, stamp);
}

void NbsPlannerNode::publish(const nbs::PlanResult& plan, const ros::Time& stamp) {
  if (plan.ok()) {
    const nbs::Candidate& best = plan.ranked.front();
    picker_localisation::GoalNode g;
    g.header.stamp = stamp;
    g.header.frame_id = map_frame_;
    g.robot_id = robot_id_;
    g.node = map_->node(best.node).name;
    g.pose = nodePose(map_->node(best.node));
    g.utility = best.utility;
    g.policy = nbs::toString(plan.policy);
    g.target_picker = best.target_picker;
    publishGoal(g);
  }
  marker_pub_.publish(candidateMarkers(plan, stamp));
  ++markers_published_;
}

visualization_msgs::MarkerArray NbsPlannerNode::candidateMarkers(const nbs::PlanResult& plan,
                                                                 const ros::Time& stamp) const {
  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  out.markers.push_back(clear);
  visualization_msgs::Marker spheres;
  spheres.header.frame_id = map_frame_;
  spheres.header.stamp = stamp;
  spheres.ns = robot_id_ + "/nbs_candidates";
  spheres.id = 0;
  spheres.type = visualization_msgs::Marker::SPHERE_LIST;
  spheres.action = visualization_msgs::Marker::ADD;
  spheres.pose.orientation.w = 1.0;
  spheres.scale.x = spheres.scale.y = spheres.scale.z = 0.5;
  for (const nbs::Candidate& c : plan.ranked) {
    geometry_msgs::Point p;
    p.x = map_->node(c.node).position.x();
    p.y = map_->node(c.node).position.y();
    p.z = 0.5;
    spheres.points.push_back(p);
    spheres.colors.push_back(utilityColour(c.utility));
  }
  if (!spheres.points.empty()) out.markers.push_back(spheres);
  // The five best with their utility as text, the goal as a tall cylinder.
  for (std::size_t i = 0; i < std::min<std::size_t>(5, plan.ranked.size()); ++i) {
    const nbs::Candidate& c = plan.ranked[i];
    visualization_msgs::Marker t;
    t.header = spheres.header;
    t.ns = robot_id_ + "/nbs_utilities";
    t.id = static_cast<int>(i);
    t.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    t.pose.position.x = map_->node(c.node).position.x();
    t.pose.position.y = map_->node(c.node).position.y();
    t.pose.position.z = 1.2;
    t.pose.orientation.w = 1.0;
    t.scale.z = 0.4;
    t.color.r = t.color.g = t.color.b = t.color.a = 1.0f;
    char text[64];
    std::snprintf(text, sizeof(text), "%.2f", c.utility);
    t.text = text;
    out.markers.push_back(t);
  }
  if (plan.ok()) {
    visualization_msgs::Marker goal;
    goal.header = spheres.header;
    goal.ns = robot_id_ + "/nbs_goal";
    goal.id = 0;
    goal.type = visualization_msgs::Marker::CYLINDER;
    goal.pose = nodePose(map_->node(plan.ranked.front().node));
    goal.pose.position.z = 1.0;
    goal.scale.x = goal.scale.y = 0.6;
    goal.scale.z = 2.0;
    goal.color.g = 0.6f;
    goal.color.b = 1.0f;
    goal.color.a = 0.7f;
    out.markers.push_back(goal);
  }
  return out;
}

bool NbsPlannerNode::getCandidates(picker_localisation::GetCandidates::Request& req,
                                   picker_localisation::GetCandidates::Response& res) {
  if (!last_plan_) planOnce();
  if (!last_plan_) return true;  // no pose yet: empty answer (diagnostics say why)
  const nbs::PlanResult& plan = *last_plan_;
  res.criteria = plan.criteria;
  const std::size_t n = req.max_candidates == 0
                            ? plan.ranked.size()
                            : std::min<std::size_t>(req.max_candidates, plan.ranked.size());
  for (std::size_t i = 0; i < n; ++i) {
    res.nodes.push_back(map_->node(plan.ranked[i].node).name);
    res.utilities.push_back(plan.ranked[i].utility);
    res.normalised_criteria.insert(res.normalised_criteria.end(), plan.ranked[i].normalised.begin(),
                                   plan.ranked[i].normalised.end());
  }
  return true;
}

void NbsPlannerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  stat.add("serving a call",
           call_goal_ ? call_goal_->target_picker + " at " + call_goal_->node : std::string("no"));
  stat.add("call goals", call_goals_);
  stat.add("call goals rejected", call_goals_rejected_);
  stat.add("call-due weight", tray_clock_->callDueWeight());
  stat.add("call status messages", call_status_messages_);
  stat.add("belief topic", beliefs_->topic());
  stat.add("beliefs of pickers not listed", beliefs_of_others_);
  std::size_t with_belief = 0;
  for (const auto& in : pickers_) {
    if (in->belief) ++with_belief;
    stat.add("beliefs received " + in->id, in->received);
    stat.add("beliefs rejected " + in->id, in->rejected);
  }
  stat.add("robot id", robot_id_);
  stat.add("policy", nbs::toString(planner_->config().policy));
  stat.add("battery level", battery_level_);
  stat.add("plans", plans_);
  stat.add("plans without goal", failed_plans_);
  stat.add("tf failures", tf_failures_);
  stat.add("stale robot poses", stale_poses_);
  stat.add("plans on the fallback belief (no what-if)", fallback_plans_);
  stat.add("other robots' goals known", peer_goals_.size());
  stat.add("other robots' goals rejected", peer_goals_rejected_);
  if (last_plan_ && last_plan_->ok()) {
    stat.add("goal", map_->node(last_plan_->ranked.front().node).name);
    stat.add("goal utility", last_plan_->ranked.front().utility);
    stat.add("candidates", last_plan_->ranked.size());
    stat.add("what-if queries", last_plan_->what_if_queries);
  }
  if (!last_problem_.empty())
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, last_problem_);
  else if (with_belief == 0 && planner_->config().policy == nbs::Policy::kEstimatedNode)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no picker belief received yet");
  else if (!last_what_if_error_.empty() && fallback_plans_ > 0 && last_plan_ && plans_ > 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                 "planning without the what-if service: " + last_what_if_error_);
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "planning");
}

}  // namespace ros_adapter
}  // namespace picker_localisation
