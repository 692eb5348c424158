#include <cmath>
#include <limits>

#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/ros/uwb_ranging_node.h"
#include "picker_localisation/sensors_ranging/ranging_node_options.h"

namespace picker_localisation {
namespace ros_adapter {

UwbRangingNode::UwbRangingNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  // The node's options; the algorithm's (config/uwb_ranging.yaml) are the struct the offline runner builds.
  sensors::UwbRangingNodeOptions node_options;
  if (!loadOptions(pnh, node_options)) return;
  const sensors::UwbRangingOptions& o = node_options.ranging;
  const core::CommonNodeOptions& common = node_options.common;
  const std::optional<core::PickerRegistry> registry_opt =
      loadPickerRegistry(node_options.fleet.pickers_file, "uwb_ranging");
  if (!registry_opt) return;
  const core::PickerRegistry& registry = *registry_opt;
  map_frame_ = common.map_frame;
  stamp_guard_ = StampGuard(common.max_future_stamp);
  tf_timeout_ = common.tf_timeout;
  base_frame_ = node_options.base_frame;
  map_ = obtainMap(nh, common);
  if (!map_) return;
  try {
    uwb_ = std::make_unique<sensors::UwbRanging>(registry, map_, o);
  } catch (const std::exception& e) {
    ROS_FATAL("uwb_ranging: %s", e.what());
    return;
  }
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_);
  pub_ = nh.advertise<picker_localisation::Observation>(common.observations_topic, 100);
  const std::vector<std::string> uwb_topics = node_options.uwb_topics;
  const std::vector<std::string> bearing_topics = node_options.bearing_topics;
  for (const std::string& t : uwb_topics) subs_.push_back(nh.subscribe(t, 200, &UwbRangingNode::onRange, this));
  for (const std::string& t : bearing_topics)
    subs_.push_back(nh.subscribe(t, 20, &UwbRangingNode::onBearings, this));
  flush_timer_ = nh.createWallTimer(ros::WallDuration(std::max(node_options.flush_period, 0.005)),
                                    &UwbRangingNode::onFlush, this);
  diagnostics_.setHardwareID("uwb_ranging");
  silence_.configure(node_options.fleet.silent_warn_after, "UWB ranges");
  diagnostics_.add("UWB ranging", this, &UwbRangingNode::diagnose);
  diagnostics_.input("uwb ranges");
  diagnostics_.input("bearings");
  diagnostics_.start(nh);
  registry_sub_ =
      followPickerList(nh, node_options.fleet, "uwb_ranging", [this](const core::PickerRegistry& r) {
        uwb_->setRegistry(r);
        ROS_INFO("uwb_ranging: picker list from the tracker: %zu picker(s)", r.size());
      });
  map_follower_ = std::make_unique<MapFollower>(
      nh, common, map_,
      [this](std::shared_ptr<const topology::TopologicalMap> m, const topology::MapChange&) {
        map_ = m;
        uwb_->setMap(std::move(m));
      });
  ok_ = true;
}

std::string UwbRangingNode::baseFrame(const std::string& robot_id) const {
  if (!base_frame_.empty()) return base_frame_;
  return robot_id.empty() ? "base_link" : robot_id + "/base_link";
}

std::optional<Eigen::Isometry2d> UwbRangingNode::mount(const std::string& base, const std::string& frame,
                                                       const ros::Time& stamp, std::string* error) {
  const std::string key = base + "|" + frame;
  auto it = mounts_.find(key);
  if (it != mounts_.end()) return it->second;
  // Mounts are static: the latest transform is the one at any stamp.
  (void)stamp;
  std::optional<Eigen::Isometry3d> t = lookupTransform(tf_buffer_, base, frame, ros::Time(0), tf_timeout_, error);
  if (!t) return std::nullopt;
  const Eigen::Isometry2d m = planar(*t);
  mounts_[key] = m;
  return m;
}

void UwbRangingNode::onRange(const picker_localisation::UwbRange::ConstPtr& msg) {
  diagnostics_.tick("uwb ranges");
  silence_.heard();
  if (stamp_guard_.clockJumpedBack()) {
    ROS_WARN("uwb_ranging: the clock jumped back: tag filters reset");
    uwb_->reset();
    have_range_ = false;
    newest_stamp_ = 0.0;
  }
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) {
    ROS_WARN_THROTTLE(5.0, "uwb_ranging: range stamped %.3f is more than %.1f s ahead of the clock: dropped",
                      msg->header.stamp.toSec(), stamp_guard_.maxFuture());
    return;
  }
  const std::string base = baseFrame(msg->robot_id);
  std::string error;
  std::optional<Eigen::Isometry2d> anchor = mount(base, msg->header.frame_id, msg->header.stamp, &error);
  std::optional<Eigen::Isometry3d> robot;
  if (anchor) robot = lookupTransform(tf_buffer_, map_frame_, base, msg->header.stamp, tf_timeout_, &error);
  if (!anchor || !robot) {
    ++tf_failures_;
    ROS_WARN_THROTTLE(5.0, "uwb_ranging: range of '%s' from '%s' dropped: no tf at %.3f (%s); %zu dropped so far",
                      msg->tag_id.c_str(), msg->header.frame_id.c_str(), msg->header.stamp.toSec(), error.c_str(),
                      tf_failures_);
    return;
  }
  sensors::UwbRangeInput in;
  in.stamp = msg->header.stamp.toSec();
  last_arrival_ = ros::WallTime::now();
  newest_stamp_ = have_range_ ? std::max(newest_stamp_, in.stamp) : in.stamp;
  have_range_ = true;
  in.robot_id = msg->robot_id;
  in.tag_id = msg->tag_id;
  in.frame_id = msg->header.frame_id;
  in.anchor_in_robot = *anchor;
  in.range = msg->range;
  in.variance = msg->variance;
  if (msg->has_pdoa) in.pdoa_angle = msg->pdoa_angle;
  std::vector<core::Observation> out;
  std::string reason;
  const sensors::UwbRejection r = uwb_->addRange(in, planar(*robot), &out, &reason);
  // A range beyond max_range is valid input outside the useful range (counted, logged at debug level only).
  if (r == sensors::UwbRejection::kOutOfRange)
    ROS_DEBUG_THROTTLE(5.0, "uwb_ranging: range ignored: %s", reason.c_str());
  else if (r != sensors::UwbRejection::kNone)
    ROS_WARN_THROTTLE(5.0, "uwb_ranging: range rejected (%s): %s", sensors::toString(r), reason.c_str());
  publish(out);
}

void UwbRangingNode::onBearings(const picker_localisation::BearingDetectionArray::ConstPtr& msg) {
  diagnostics_.tick("bearings");
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) return;  // counted by the guard
  std::string error;
  std::optional<Eigen::Isometry2d> cam = mount(baseFrame(msg->robot_id), msg->header.frame_id, msg->header.stamp, &error);
  if (!cam) {
    ++tf_failures_;
    ROS_WARN_THROTTLE(5.0, "uwb_ranging: camera detections from '%s' dropped: no tf (%s)",
                      msg->header.frame_id.c_str(), error.c_str());
    return;
  }
  sensors::CameraBearings set;
  set.stamp = msg->header.stamp.toSec();
  const double yaw = std::atan2(cam->linear()(1, 0), cam->linear()(0, 0));
  for (const auto& d : msg->detections) {
    if (!std::isfinite(d.bearing)) continue;
    set.bearings.push_back({cam->translation(), d.bearing + yaw, 0.0});
  }
  uwb_->addBearings(set);
  ++bearing_sets_;
}

// Batches close on message stamps (the newest range seen), so a delayed or replayed stream is batched the same
// way; when no range has arrived for batch_window s of wall time, every open batch is closed.
void UwbRangingNode::onFlush(const ros::WallTimerEvent&) {
  if (!have_range_) return;
  std::vector<core::Observation> out;
  const bool quiet = (ros::WallTime::now() - last_arrival_).toSec() > uwb_->options().batch_window;
  uwb_->flush(quiet ? std::numeric_limits<double>::infinity() : newest_stamp_, &out);
  publish(out);
}

void UwbRangingNode::publish(const std::vector<core::Observation>& obs) {
  for (const core::Observation& o : obs) {
    pub_.publish(toMsg(o, *map_, map_frame_));
    ++published_;
  }
}

void UwbRangingNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const sensors::UwbCounters& c = uwb_->counters();
  stat.add("received", c.received + tf_failures_);
  stat.add("accepted", c.accepted);
  stat.add("stamped in the future (dropped)", stamp_guard_.futureStamps());
  stat.add("clock jumps back", stamp_guard_.jumps());
  stat.add("dropped: no tf", tf_failures_);
  stat.add("rejected: unknown tag", c.unknown_tag);
  stat.add("rejected: not finite", c.not_finite);
  stat.add("rejected: negative range", c.negative_range);
  stat.add("rejected: beyond max_range", c.out_of_range);
  stat.add("rejected: out of order", c.out_of_order);
  stat.add("RHF updates", c.updates);
  stat.add("suppressed (ambiguous / at grid edge)", c.suppressed);
  stat.add("camera detection sets", bearing_sets_);
  stat.add("published", published_);
  const std::size_t bad = tf_failures_ + c.unknown_tag + c.not_finite + c.negative_range + c.out_of_range + c.out_of_order;
  if (c.accepted == 0 && bad > 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no usable UWB ranges yet");
  else
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "running; %zu range(s) dropped or rejected", bad);
  silence_.report(stat);
}

}  // namespace ros_adapter
}  // namespace picker_localisation
