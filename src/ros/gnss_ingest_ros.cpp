#include <cmath>
#include <sstream>

#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/ros/ranging_nodes.h"

namespace picker_localisation {
namespace ros_adapter {

GnssIngestNode::GnssIngestNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const std::optional<core::PickerRegistry> registry_opt = loadPickerRegistry(pnh, "gnss_ingest");
  if (!registry_opt) return;
  const core::PickerRegistry& registry = *registry_opt;
  std::string datum_file;
  if (!pnh.getParam("datum_file", datum_file)) {
    ROS_FATAL("gnss_ingest: parameter ~datum_file (config/datum.yaml) is required");
    return;
  }
  std::unique_ptr<sensors::GeodeticDatum> datum;
  try {
    datum = std::make_unique<sensors::GeodeticDatum>(sensors::GeodeticDatum::load(datum_file));
  } catch (const std::exception& e) {
    ROS_FATAL("gnss_ingest: %s", e.what());
    return;
  }
  // One options schema, shared with the offline runner (config/gnss_ingest.yaml keys).
  sensors::GnssIngestOptions o;
  if (!loadOptions(pnh, o)) return;
  pnh.param<std::string>("frame_id", frame_id_, "map");
  stamp_guard_ = StampGuard(pnh.param("max_future_stamp", 10.0));
  double map_timeout = 30.0;
  pnh.param("map_timeout", map_timeout, map_timeout);
  map_ = obtainMap(nh, pnh, map_timeout);
  if (!map_) return;

  std::string topic;
  pnh.param<std::string>("observation_topic", topic, "/observations");
  pub_ = nh.advertise<picker_localisation::Observation>(topic, 100);
  for (const core::PickerConfig& p : registry.pickers()) {
    if (p.gnss_topic.empty()) continue;
    ingest_.emplace_back(p.id, map_, *datum, o);
    const std::size_t i = ingest_.size() - 1;
    subs_.push_back(nh.subscribe<sensor_msgs::NavSatFix>(
        p.gnss_topic, 50, [this, i](const sensor_msgs::NavSatFix::ConstPtr& m) { onFix(m, i); }));
    ROS_INFO("gnss_ingest: %s <- %s", p.id.c_str(), p.gnss_topic.c_str());
  }
  if (ingest_.empty()) ROS_WARN("gnss_ingest: no picker in ~pickers_file has a gnss_topic");
  updater_.setHardwareID("gnss_ingest");
  updater_.add("GNSS ingestion", this, &GnssIngestNode::diagnose);
  diag_timer_ = nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { updater_.update(); });
  ok_ = true;
}

void GnssIngestNode::onFix(const sensor_msgs::NavSatFix::ConstPtr& msg, std::size_t i) {
  if (stamp_guard_.clockJumpedBack()) {
    // A bag replayed with -l or a simulator restart: forget every picker's fix history (else every later fix
    // would be "not after the last accepted one" until the new stamps overtake the old).
    ROS_WARN("gnss_ingest: the clock jumped back: fix histories reset");
    for (auto& ingest : ingest_) ingest = sensors::GnssIngest(ingest.pickerId(), map_, ingest.datum(), ingest.options());
  }
  sensors::GnssIngest& g = ingest_[i];
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) {
    ROS_WARN_THROTTLE(5.0, "gnss_ingest: %s: fix stamped %.3f is more than %.1f s ahead of the clock: rejected",
                      g.pickerId().c_str(), msg->header.stamp.toSec(), stamp_guard_.maxFuture());
    return;
  }
  sensors::GnssResult r = g.process(gnssFixFromMsg(*msg));
  if (!r.accepted()) {
    ROS_WARN_THROTTLE(5.0, "gnss_ingest: %s: fix at %.3f rejected (%s): %s", g.pickerId().c_str(),
                      msg->header.stamp.toSec(), sensors::toString(r.rejection), r.reason.c_str());
    return;
  }
  if (r.blackout_ended > 0.0)
    ROS_INFO("gnss_ingest: %s: GNSS back after a %.1f s blackout", g.pickerId().c_str(), r.blackout_ended);
  pub_.publish(toMsg(*r.observation, *map_, frame_id_));
  ++published_;
}

void GnssIngestNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const double now = ros::Time::now().toSec();
  std::size_t blackout = 0, rejected = 0;
  stat.add("fixes stamped in the future (rejected)", stamp_guard_.futureStamps());
  stat.add("clock jumps back", stamp_guard_.jumps());
  for (const sensors::GnssIngest& g : ingest_) {
    const sensors::GnssCounters& c = g.counters();
    const std::string k = g.pickerId() + " ";
    stat.add(k + "received", c.received);
    stat.add(k + "accepted", c.accepted);
    stat.add(k + "rejected no_fix/not_finite/negative_cov/out_of_order/jump",
             std::to_string(c.no_fix) + "/" + std::to_string(c.not_finite) + "/" + std::to_string(c.negative_covariance) +
                 "/" + std::to_string(c.out_of_order) + "/" + std::to_string(c.impossible_jump));
    stat.add(k + "blackouts (ended)", c.blackouts);
    stat.add(k + "longest blackout [s]", c.longest_blackout);
    const double age = g.ageOfLastFix(now);
    stat.add(k + "age of last fix [s]", std::isfinite(age) ? age : -1.0);
    if (g.inBlackout(now)) ++blackout;
    rejected += c.received - c.accepted;
  }
  stat.add("published", published_);
  if (blackout > 0)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%zu picker(s) in GNSS blackout", blackout);
  else if (rejected > 0)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "running; %zu fix(es) rejected so far", rejected);
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
}

}  // namespace ros_adapter
}  // namespace picker_localisation
