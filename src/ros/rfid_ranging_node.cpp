#include <cmath>

#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/ros/rfid_ranging_node.h"
#include "picker_localisation/sensors_ranging/ranging_node_options.h"

namespace picker_localisation {
namespace ros_adapter {

RfidRangingNode::RfidRangingNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  // The node's options; the algorithm's (config/rfid_ranging.yaml) are the struct the offline runner builds.
  sensors::RfidRangingNodeOptions node_options;
  if (!loadOptions(pnh, node_options)) return;
  const sensors::RfidModelOptions& o = node_options.model;
  const core::CommonNodeOptions& common = node_options.common;
  const std::optional<core::PickerRegistry> registry_opt =
      loadPickerRegistry(node_options.fleet.pickers_file, "rfid_ranging");
  if (!registry_opt) return;
  const core::PickerRegistry& registry = *registry_opt;
  map_frame_ = common.map_frame;
  stamp_guard_ = StampGuard(common.max_future_stamp);
  tf_timeout_ = common.tf_timeout;
  map_ = obtainMap(nh, common);
  if (!map_) return;
  try {
    model_ = std::make_unique<sensors::RfidObservationModel>(registry, map_, o);
  } catch (const std::exception& e) {
    ROS_FATAL("rfid_ranging: %s", e.what());
    return;
  }
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_);
  pub_ = nh.advertise<picker_localisation::Observation>(common.observations_topic, 100);
  const std::vector<std::string> topics = node_options.rfid_topics;
  for (const std::string& t : topics) subs_.push_back(nh.subscribe(t, 100, &RfidRangingNode::onReading, this));
  diagnostics_.setHardwareID("rfid_ranging");
  silence_.configure(node_options.fleet.silent_warn_after, "RFID reads");
  diagnostics_.add("RFID ranging", this, &RfidRangingNode::diagnose);
  diagnostics_.input("rfid reads");
  diagnostics_.start(nh);
  registry_sub_ =
      followPickerList(nh, node_options.fleet, "rfid_ranging", [this](const core::PickerRegistry& r) {
        model_->setRegistry(r);
        ROS_INFO("rfid_ranging: picker list from the tracker: %zu picker(s)", r.size());
      });
  map_follower_ = std::make_unique<MapFollower>(
      nh, common, map_,
      [this](std::shared_ptr<const topology::TopologicalMap> m, const topology::MapChange&) {
        map_ = m;
        model_->setMap(std::move(m));
      });
  ok_ = true;
}

void RfidRangingNode::onReading(const picker_localisation::RfidReading::ConstPtr& msg) {
  diagnostics_.tick("rfid reads");
  silence_.heard();
  if (stamp_guard_.clockJumpedBack()) {
    ROS_WARN("rfid_ranging: the clock jumped back: read histories reset");
    model_->reset();
  }
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) {  // adopting it would reject every later read
    ROS_WARN_THROTTLE(5.0, "rfid_ranging: read stamped %.3f is more than %.1f s ahead of the clock: dropped",
                      msg->header.stamp.toSec(), stamp_guard_.maxFuture());
    return;
  }
  std::string error;
  const std::optional<Eigen::Isometry3d> t =
      lookupTransform(tf_buffer_, map_frame_, msg->header.frame_id, msg->header.stamp, tf_timeout_, &error);
  if (!t) {
    ++tf_failures_;
    ROS_WARN_THROTTLE(5.0, "rfid_ranging: read of '%s' dropped: no tf %s <- '%s' at %.3f (%s); %zu dropped so far",
                      msg->tag_id.c_str(), map_frame_.c_str(), msg->header.frame_id.c_str(),
                      msg->header.stamp.toSec(), error.c_str(), tf_failures_);
    return;
  }
  const Eigen::Isometry2d p = planar(*t);
  sensors::RfidRead read;
  read.stamp = msg->header.stamp.toSec();
  read.robot_id = msg->robot_id;
  read.frame_id = msg->header.frame_id;
  read.tag_id = msg->tag_id;
  read.antenna_pose << p.translation(), std::atan2(p.linear()(1, 0), p.linear()(0, 0));
  read.rssi = msg->rssi;
  sensors::RfidResult r = model_->process(read);
  if (!r.accepted()) {
    ROS_WARN_THROTTLE(5.0, "rfid_ranging: read rejected (%s): %s", sensors::toString(r.rejection), r.reason.c_str());
    return;
  }
  pub_.publish(toMsg(*r.observation, *map_, map_frame_));
  ++published_;
  for (const core::Observation& n : r.negative) {
    pub_.publish(toMsg(n, *map_, map_frame_));
    ++published_;
  }
}

void RfidRangingNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const sensors::RfidCounters& c = model_->counters();
  stat.add("received", c.received + tf_failures_);
  stat.add("accepted", c.accepted);
  stat.add("stamped in the future (dropped)", stamp_guard_.futureStamps());
  stat.add("clock jumps back", stamp_guard_.jumps());
  stat.add("dropped: no tf", tf_failures_);
  stat.add("rejected: unknown tag", c.unknown_tag);
  stat.add("rejected: not finite", c.not_finite);
  stat.add("rejected: weak signal", c.weak_signal);
  stat.add("rejected: out of order", c.out_of_order);
  stat.add("negative observations", c.negative_sent);
  stat.add("published", published_);
  const std::size_t bad = tf_failures_ + c.unknown_tag + c.not_finite + c.out_of_order;
  if (c.accepted == 0 && bad > 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no usable RFID reads yet");
  else
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "running; %zu read(s) dropped or rejected", bad);
  silence_.report(stat);
}

}  // namespace ros_adapter
}  // namespace picker_localisation
