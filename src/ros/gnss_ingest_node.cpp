#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <ros/names.h>

#include <picker_localisation/GnssBias.h>

#include "picker_localisation/ros/gnss_ingest_node.h"
#include "picker_localisation/ros/last_value_publisher.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/sensors_ranging/ranging_node_options.h"

namespace picker_localisation {
namespace ros_adapter {

GnssIngestNode::GnssIngestNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  // The node's options; the algorithm's (config/gnss_ingest.yaml) are the struct the offline runner builds.
  sensors::GnssIngestNodeOptions node_options;
  if (!loadOptions(pnh, node_options)) return;
  const sensors::GnssIngestOptions& o = node_options.ingest;
  const core::CommonNodeOptions& common = node_options.common;
  const std::optional<core::PickerRegistry> registry_opt =
      loadPickerRegistry(node_options.fleet.pickers_file, "gnss_ingest");
  if (!registry_opt) return;
  const core::PickerRegistry& registry = *registry_opt;
  datum_file_ = node_options.datum_file;
  datum_source_ = node_options.datum_source;
  frame_id_ = common.map_frame;
  stamp_guard_ = StampGuard(common.max_future_stamp);
  map_ = obtainMap(nh, common);
  if (!map_) return;
  if (!loadDatum()) return;

  options_ = o;
  fleet_ = std::make_unique<sensors::GnssFleet>(map_, *datum_, o);
  const std::string topic = common.observations_topic;
  bias_prefix_ = node_options.bias_topic_prefix;
  ordering_latency_ = orderingLatency(common.ordering_latency, 0.2);
  // As tpf_tracker: above ~on_demand_topics_above pickers a bias topic exists while someone subscribes.
  on_demand_.start(
      nh, node_options.fleet, registry.size(), [this] { return pickers_.size(); },
      [this] {
        for (auto& p : pickers_) advertiseBias(*p);
      });
  ordering_ = core::StampOrderedBuffer<Input>(ordering_latency_, 10000 + 20 * registry.size());
  pub_ = nh.advertise<picker_localisation::Observation>(topic, 1000);
  markers_pub_ = CountedPublisher::advertise<visualization_msgs::MarkerArray>(pnh, "bias_markers", 2, {}, true);
  for (const core::PickerConfig& p : registry.pickers()) addPicker(p);
  if (o.association.enabled && o.association.belief_weight > 0.0) {
    beliefs_ =
        std::make_unique<FleetBeliefs>(nh, node_options.fleet.belief_topic,
                                       [this](const picker_localisation::PickerBelief& b) { onBelief(b); });
    beliefs_->follow(registry.ids());
  }
  subs_.push_back(followPickerList(nh, node_options.fleet, "gnss_ingest",
                                   [this](const core::PickerRegistry& r) { onRegistry(r); }));
  subscribePeople(nh, node_options, registry);
  if (!o.bias.sighting_sensors.empty() || (o.association.enabled && !o.association.identity_sensors.empty()))
    subs_.push_back(nh.subscribe<picker_localisation::Observation>(
        topic, 200, [this](const picker_localisation::Observation::ConstPtr& m) { onIdentified(m); }));
  if (ordering_latency_ > 0.0)
    ordering_timer_ = nh.createTimer(ros::Duration(std::min(0.05, ordering_latency_ / 4.0)),
                                     [this](const ros::TimerEvent&) { releaseOrdered(); });
  if (pickers_.empty()) ROS_WARN("gnss_ingest: no picker in ~pickers_file has a gnss_topic");
  ROS_INFO("gnss_ingest: %zu picker(s) with GNSS, ordering latency %.2f s (%s)", pickers_.size(), ordering_latency_,
           ordering_latency_ > 0.0 ? "stamp-ordered replay" : "processed on arrival");
  diagnostics_.setHardwareID("gnss_ingest");
  silence_.configure(node_options.fleet.silent_warn_after, "GNSS fixes");
  diagnostics_.add("GNSS ingestion", this, &GnssIngestNode::diagnose);
  for (const char* input : {"fixes", "people", "identifying observations", "beliefs"}) diagnostics_.input(input);
  diagnostics_.start(nh);
  map_follower_ =
      std::make_unique<MapFollower>(nh, common, map_,
                                    [this](std::shared_ptr<const topology::TopologicalMap> m,
                                           const topology::MapChange& c) { adoptMap(std::move(m), c); });
  ok_ = true;
}

// The datum: the map's own (tmap2 meta.datum_*, LCAS add_datum) unless ~datum_source says file; the file's
// when the map has none. False after one FATAL line.
bool GnssIngestNode::loadDatum() {
  try {
    if (useMapDatum(datum_source_, *map_)) {
      const core::DatumConfig c = map_->datum()->config();
      datum_ = std::make_unique<core::GeodeticDatum>(c);
      ROS_INFO("gnss_ingest: datum from the map (%.7f, %.7f, %.1f m; ~datum_source file uses %s instead)",
               c.latitude, c.longitude, c.altitude,
               datum_file_.empty() ? "~datum_file" : datum_file_.c_str());
    } else {
      if (datum_file_.empty())
        throw std::runtime_error(
            "parameter ~datum_file (config/datum.yaml) is required: the map has no datum");
      datum_ = std::make_unique<core::GeodeticDatum>(core::GeodeticDatum::load(datum_file_));
      ROS_INFO("gnss_ingest: datum from %s%s", datum_file_.c_str(),
               map_->datum() ? " (~datum_source file: the map's own datum is not used)" : "");
    }
  } catch (const std::exception& e) {
    ROS_FATAL("gnss_ingest: %s", e.what());
    return false;
  }
  return true;
}

// Anonymous people to associate (leg_detector's), other detectors' people and the pickers' own map-frame
// positions (an LCAS robot's people and pickers' poses).
void GnssIngestNode::subscribePeople(ros::NodeHandle& nh, const sensors::GnssIngestNodeOptions& node_options,
                                     const core::PickerRegistry& registry) {
  if (!node_options.person_observation_topic
           .empty()) {  // with associate_people false the people are passed on unchanged
    subs_.push_back(nh.subscribe<picker_localisation::Observation>(
        node_options.person_observation_topic, 200,
        [this](const picker_localisation::Observation::ConstPtr& m) { onPerson(m); }));
    ROS_INFO("gnss_ingest: %s anonymous people from %s",
             options_.association.enabled ? "associating" : "passing on",
             node_options.person_observation_topic.c_str());
  }
  people_pose_sensor_ = node_options.people_pose_sensor;
  people_pose_sigma_ = node_options.people_pose_sigma;
  pose_sensor_ = node_options.pose_sensor;
  pose_topic_format_ = node_options.pose_topic_format;
  max_people_per_message_ = static_cast<std::size_t>(node_options.max_people_per_message);
  for (const std::string& t : node_options.people_pose_topics)
    subs_.push_back(nh.subscribe<geometry_msgs::PoseArray>(
        t, 20, [this, t](const geometry_msgs::PoseArray::ConstPtr& m) { onPeoplePoses(m, t); }));
  followPoseTopics(registry.ids());
}

void GnssIngestNode::adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                              const topology::MapChange& change) {
  // The map's own datum moved (LCAS add_datum again): fixes are placed in the new frame from now on.
  bool datum_moved = false;
  if (change.datum_changed) {
    try {
      if (useMapDatum(datum_source_, *map)) {
        datum_ = std::make_unique<core::GeodeticDatum>(map->datum()->config());
        datum_moved = true;
      } else if (datum_source_ != "file" && !datum_file_.empty()) {  // the map's datum is gone: the file's
        datum_ = std::make_unique<core::GeodeticDatum>(core::GeodeticDatum::load(datum_file_));
        datum_moved = true;
      }
    } catch (const std::exception& e) {
      ROS_ERROR("gnss_ingest: the new map's datum is not used, keeping the current one: %s", e.what());
    }
  }
  map_ = std::move(map);
  fleet_->adoptMap(map_, *datum_, datum_moved);
  const std::size_t dropped = ordering_.size();
  ordering_.clear();  // people decoded on the old map's nodes
  if (dropped > 0)
    ROS_WARN("gnss_ingest: %zu fix(es) / people waiting for stamp order dropped with the old map", dropped);
  if (datum_moved) ROS_INFO("gnss_ingest: datum of the new map taken; fix histories restart in its frame");
}

bool GnssIngestNode::addPicker(const core::PickerConfig& p) {
  if (p.gnss_topic.empty()) return true;
  // Made whole before it is listed: a picker is either subscribed and counted, or not there at all.
  sensors::GnssFleet::Picker* core = fleet_->add(p.id);
  if (!core) {
    ++pickers_refused_;
    ROS_WARN("gnss_ingest: picker %s listed twice: followed once", p.id.c_str());
    return false;
  }
  auto picker = std::make_unique<Picker>(p, core);
  Picker* raw = picker.get();
  try {
    const std::string problem = gnssTopicProblem(p.gnss_topic);
    if (!problem.empty()) throw std::runtime_error(problem);
    raw->fix_sub = nh_.subscribe<sensor_msgs::NavSatFix>(
        p.gnss_topic, 50, [this, raw](const sensor_msgs::NavSatFix::ConstPtr& m) { onFix(m, raw); },
        ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
    raw->bias_topic = nh_.resolveName(bias_prefix_ + "/" + p.id + "/gnss_bias");
  } catch (const std::exception& e) {
    ++pickers_refused_;
    fleet_->remove(p.id);
    ROS_WARN("gnss_ingest: picker %s not followed: %s", p.id.c_str(), e.what());
    return false;
  }
  pickers_.push_back(std::move(picker));
  by_id_[p.id] = raw;
  advertiseBias(*raw);
  ROS_INFO("gnss_ingest: %s <- %s", p.id.c_str(), p.gnss_topic.c_str());
  return true;
}

void GnssIngestNode::advertiseBias(Picker& p) {
  advertiseWhileWanted(p.bias_pub, p.bias_topic, on_demand_.demand(),
                       [&] { p.bias_pub.advertise(nh_, p.bias_topic, 5); });
}

void GnssIngestNode::onRegistry(const core::PickerRegistry& registry) {
  // The tracker's list is the truth: pickers it no longer tracks go, new ones (with a GNSS topic) come, one whose
  // topic changed is subscribed again.
  ++registry_updates_;
  std::unordered_map<std::string, core::PickerConfig> wanted;
  std::vector<std::string> order;
  for (const core::PickerConfig& c : registry.pickers()) {
    wanted.emplace(c.id, c);
    order.push_back(c.id);
  }
  std::size_t removed = 0, added = 0;
  for (auto it = pickers_.begin(); it != pickers_.end();) {
    const auto w = wanted.find((*it)->config.id);
    if (w == wanted.end() || w->second.gnss_topic != (*it)->config.gnss_topic) {
      by_id_.erase((*it)->config.id);
      fleet_->remove((*it)->config.id);
      it = pickers_.erase(it);  // its subscriptions and bias topic go with it
      ++removed;
    } else {
      ++it;
    }
  }
  for (const std::string& id : order)
    if (!by_id_.count(id) && !wanted[id].gnss_topic.empty() && addPicker(wanted[id])) ++added;
  if (beliefs_) beliefs_->follow(order);
  followPoseTopics(order);
  if (added + removed > 0)
    ROS_INFO("gnss_ingest: picker list from the tracker: %zu added, %zu removed, %zu with GNSS", added, removed,
             pickers_.size());
}

bool GnssIngestNode::checkClock() {
  if (!stamp_guard_.clockJumpedBack()) return false;
  // A bag replayed with -l or a simulator restart: forget every picker's fix history, bias estimate, the
  // beliefs and what waits for stamp order (else every later fix would be "not after the last accepted one").
  ROS_WARN("gnss_ingest: the clock jumped back: fix histories, bias estimates and beliefs reset");
  fleet_->reset();
  ordering_.clear();
  return true;
}

void GnssIngestNode::onFix(const sensor_msgs::NavSatFix::ConstPtr& msg, Picker* picker) {
  diagnostics_.tick("fixes");
  checkClock();
  silence_.heard();
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) {
    ROS_WARN_THROTTLE(5.0, "gnss_ingest: %s: fix stamped %.3f is more than %.1f s ahead of the clock: rejected",
                      picker->config.id.c_str(), msg->header.stamp.toSec(), stamp_guard_.maxFuture());
    return;
  }
  Input in;
  in.picker = picker->config.id;
  in.fix = gnssFixFromMsg(*msg);
  if (ordering_latency_ <= 0.0 || !std::isfinite(in.fix.stamp)) {
    processFix(*picker, in.fix);  // (a NaN stamp is rejected there with its reason)
    return;
  }
  ordering_.push(in.fix.stamp, "fix|" + in.picker, std::move(in));
}

void GnssIngestNode::onPerson(const picker_localisation::Observation::ConstPtr& msg) {
  diagnostics_.tick("people");
  checkClock();
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) {
    ROS_WARN_THROTTLE(5.0, "gnss_ingest: person observation stamped %.3f is more than %.1f s ahead of the clock",
                      msg->header.stamp.toSec(), stamp_guard_.maxFuture());
    return;
  }
  std::size_t unknown = 0;
  Input in;
  in.is_fix = false;
  in.person = fromMsg(*msg, *map_, &unknown);
  const std::string problem = core::validateObservation(in.person, *map_);
  if (!problem.empty() || unknown > 0) {
    ++bad_people_;
    ROS_WARN_THROTTLE(5.0, "gnss_ingest: person observation from %s dropped: %s", msg->robot_id.c_str(),
                      problem.empty() ? "node names not in the map" : problem.c_str());
    return;
  }
  if (msg->identifying) {  // already identified (e.g. by another associator): pass through
    pub_.publish(*msg);
    ++published_;
    return;
  }
  std::ostringstream key;
  key.precision(17);
  key << "person|" << msg->robot_id << "|" << msg->position.x << "|" << msg->position.y;
  if (!in.person.position)
    key << "|" << in.person.nodes.size() << "|" << in.person.totalLikelihood();  // negative
  acceptPerson(std::move(in.person), key.str());
}

void GnssIngestNode::acceptPerson(core::Observation person, const std::string& key) {
  if (ordering_latency_ <= 0.0) {
    processPerson(person);
    return;
  }
  Input in;
  in.is_fix = false;
  in.person = std::move(person);
  const double stamp = in.person.stamp;
  ordering_.push(stamp, key, std::move(in));
}

void GnssIngestNode::onIdentified(const picker_localisation::Observation::ConstPtr& msg) {
  diagnostics_.tick("identifying observations");
  // Cheap filter before converting: this topic carries every observation of the fleet.
  if (!fleet_->wantsIdentified(msg->identifying, msg->sensor)) return;
  const bool evidence = options_.association.enabled && options_.association.isIdentitySensor(msg->sensor);
  checkClock();
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) return;
  Input in;
  in.is_fix = false;
  in.is_sighting = true;
  in.person = fromMsg(*msg, *map_);
  if (!in.person.position && !evidence) return;
  if (ordering_latency_ <= 0.0) {
    useIdentified(in.person);
    return;
  }
  ordering_.push(in.person.stamp, "sighting|" + msg->sensor + "|" + msg->picker_id + "|" + msg->robot_id, std::move(in));
}

void GnssIngestNode::useIdentified(const core::Observation& obs) {
  fleet_->useIdentified(obs);
}

void GnssIngestNode::onBelief(const picker_localisation::PickerBelief& msg) {
  diagnostics_.tick("beliefs");
  const auto it = by_id_.find(msg.picker_id);
  if (it == by_id_.end()) return;  // a picker without GNSS here
  if (msg.nodes.empty()) return;   // not initialised yet (or reset): nothing to associate with
  // Kept beliefs are used by stamp: one from the future would hide every later belief of the picker.
  if (stamp_guard_.tooFarInFuture(msg.header.stamp) || msg.nodes.size() > map_->numNodes()) {
    ++bad_beliefs_;
    ROS_WARN_THROTTLE(
        10.0, "gnss_ingest: belief of %s dropped: stamped %.3f (more than %.1f s ahead) or %zu nodes",
        msg.picker_id.c_str(), msg.header.stamp.toSec(), stamp_guard_.maxFuture(), msg.nodes.size());
    return;
  }
  BeliefSupport support = beliefSupport(msg, *map_);
  if (!fleet_->addBelief(msg.picker_id, msg.header.stamp.toSec(), support.nodes, std::move(support.masses))) {
    ++bad_beliefs_;
    ROS_WARN_THROTTLE(10.0, "gnss_ingest: belief of %s dropped: no node of this map with a positive mass",
                      msg.picker_id.c_str());
  }
}

void GnssIngestNode::releaseOrdered() {
  if (checkClock()) return;
  // People of one robot's sensor with one stamp come out next to each other (keys "person|<robot>|..."): they
  // are associated together, each picker at most one of them (sensors::associatePeople).
  std::vector<core::Observation> people;
  auto flushPeople = [&]() {
    if (!people.empty()) processPeople(people);
    people.clear();
  };
  for (auto& item : ordering_.release(ros::Time::now().toSec())) {
    Input& in = item.second;
    if (!in.is_fix && !in.is_sighting) {
      if (!people.empty() &&
          (in.person.stamp != people.front().stamp || in.person.robot_id != people.front().robot_id ||
           in.person.sensor != people.front().sensor))
        flushPeople();
      people.push_back(std::move(in.person));
      continue;
    }
    flushPeople();
    if (in.is_fix) {
      const auto it = by_id_.find(in.picker);
      if (it != by_id_.end()) processFix(*it->second, in.fix);
    } else {
      useIdentified(in.person);
    }
  }
  flushPeople();
}

bool GnssIngestNode::inMapFrame(const std::string& frame, const char* what) {
  if (frame.empty() || frame == frame_id_ || frame == "/" + frame_id_) return true;
  ++bad_poses_;
  ROS_WARN_THROTTLE(5.0, "gnss_ingest: %s in frame '%s' dropped: positions must be in the map frame '%s'", what,
                    frame.c_str(), frame_id_.c_str());
  return false;
}

void GnssIngestNode::onPeoplePoses(const geometry_msgs::PoseArray::ConstPtr& msg, const std::string& topic) {
  checkClock();
  if (stamp_guard_.tooFarInFuture(msg->header.stamp) || !inMapFrame(msg->header.frame_id, "people poses")) return;
  if (msg->poses.size() > max_people_per_message_) {
    // Not a crowd a robot sees: a broken or hostile detector. Refused whole, so it moves no belief.
    bad_people_ += msg->poses.size();
    ++people_arrays_refused_;
    ROS_WARN_THROTTLE(5.0,
                      "gnss_ingest: %zu people in one message on %s, more than ~max_people_per_message %zu: "
                      "dropped",
                      msg->poses.size(), topic.c_str(), max_people_per_message_);
    return;
  }
  std::size_t k = 0, dropped = 0;
  for (const auto& pose : msg->poses) {
    const Eigen::Vector2d at(pose.position.x, pose.position.y);
    if (!at.allFinite() || options_.farFromMap(*map_, at)) {
      ++bad_people_;
      ++dropped;
      continue;
    }
    core::Observation person;  // anonymous, as a leg_detector's person
    person.stamp = msg->header.stamp.toSec();
    person.sensor = people_pose_sensor_;
    person.position = at;
    person.position_covariance = Eigen::Matrix2d::Identity() * people_pose_sigma_ * people_pose_sigma_;
    core::setGaussianLikelihood(person, *map_, at, person.position_covariance);
    if (person.empty()) {
      ++bad_people_;  // off the map
      ++dropped;
      continue;
    }
    acceptPerson(std::move(person), topic + "|" + std::to_string(k++));
  }
  if (dropped > 0)
    ROS_WARN_THROTTLE(5.0,
                      "gnss_ingest: %zu of %zu people on %s dropped: position not finite or farther than "
                      "max_map_distance %.0f m from the map",
                      dropped, msg->poses.size(), topic.c_str(), options_.max_map_distance);
}

void GnssIngestNode::followPoseTopics(const std::vector<std::string>& ids) {
  if (pose_topic_format_.empty()) return;
  followIds(pose_subs_, ids, [this](const std::string& id) {
    std::string topic = pose_topic_format_;
    for (std::size_t at = topic.find("{id}"); at != std::string::npos; at = topic.find("{id}"))
      topic.replace(at, 4, id);
    return nh_.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
        topic, 20, [this, id](const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& m) { onPickerPose(m, id); });
  });
}

void GnssIngestNode::onPickerPose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& msg,
                                  const std::string& picker) {
  checkClock();
  if (stamp_guard_.tooFarInFuture(msg->header.stamp) || !inMapFrame(msg->header.frame_id, "picker pose")) return;
  const auto& c = msg->pose.covariance;  // row-major 6x6 (x, y, z, rotations): the x-y block
  Eigen::Matrix2d cov;
  cov << c[0], c[1], c[6], c[7];
  const Eigen::Vector2d at(msg->pose.pose.position.x, msg->pose.pose.position.y);
  cov = 0.5 * (cov + cov.transpose());
  if (!at.allFinite() || !core::isCovariance2d(cov)) {
    ++bad_poses_;
    ROS_WARN_THROTTLE(5.0, "gnss_ingest: pose of %s dropped: position or covariance not finite / not PSD",
                      picker.c_str());
    return;
  }
  if (double off = 0.0; options_.farFromMap(*map_, at, &off)) {
    // As a fix's check: a pose far off the map would be snapped to its nearest node and re-initialise there.
    ++bad_poses_;
    ROS_WARN_THROTTLE(
        5.0, "gnss_ingest: pose of %s dropped: %.0f m from the nearest map node (max_map_distance %.0f m)",
        picker.c_str(), off, options_.max_map_distance);
    return;
  }
  core::Observation obs;
  obs.stamp = msg->header.stamp.toSec();
  obs.sensor = pose_sensor_;
  obs.picker_id = picker;
  obs.identifying = true;
  obs.position = at;
  obs.position_covariance = cov;
  core::GaussianLikelihoodOptions lo = options_.likelihoodOptions();
  core::setGaussianLikelihood(obs, *map_, at, cov, lo);
  if (obs.empty()) {
    ++bad_poses_;
    return;
  }
  pub_.publish(toMsg(obs, *map_, frame_id_));
  ++published_;
  ++picker_poses_;
}

void GnssIngestNode::processFix(Picker& picker, const core::GnssFix& fix) {
  const sensors::GnssIngest& g = picker.core->ingest;
  const sensors::GnssResult r = fleet_->processFix(*picker.core, fix);
  if (!r.accepted()) {
    ROS_WARN_THROTTLE(5.0, "gnss_ingest: %s: fix at %.3f rejected (%s): %s", g.pickerId().c_str(), fix.stamp,
                      sensors::toString(r.rejection), r.reason.c_str());
    return;
  }
  if (r.blackout_ended > 0.0)
    ROS_INFO("gnss_ingest: %s: GNSS back after a %.1f s blackout", g.pickerId().c_str(), r.blackout_ended);
  pub_.publish(toMsg(*r.observation, *map_, frame_id_));
  ++published_;
  publishBias(picker, fix.stamp, r);
}

void GnssIngestNode::processPerson(const core::Observation& person) {
  processPeople({person});
}

void GnssIngestNode::processPeople(const std::vector<core::Observation>& people) {
  for (const sensors::AssociationResult& a : fleet_->associate(people)) {
    if (a.picker >= 0 && !a.bias.accepted)
      ROS_DEBUG("gnss_ingest: %s: sighting not used for the bias: %s", a.observation.picker_id.c_str(),
                a.bias.reason.c_str());
    if (a.concerns_nobody) continue;
    pub_.publish(toMsg(a.observation, *map_, frame_id_));
    ++published_;
  }
}

void GnssIngestNode::publishBias(Picker& picker, double stamp, const sensors::GnssResult& r) {
  const sensors::GnssIngest& g = picker.core->ingest;
  const sensors::GnssBiasEstimator& b = g.bias();
  const bool used = b.usable(stamp);
  const Eigen::Vector2d bias = b.applied(stamp);
  const Eigen::Matrix2d cov = b.appliedCovariance(stamp);
  picker_localisation::GnssBias m;
  m.header.stamp.fromSec(std::max(0.0, stamp));
  m.header.frame_id = frame_id_;
  m.picker_id = g.pickerId();
  m.estimated = used;
  m.bias.x = bias.x();
  m.bias.y = bias.y();
  m.covariance = {cov(0, 0), cov(0, 1), cov(1, 0), cov(1, 1)};
  m.sighting_age = b.sighted() ? stamp - b.lastSighting() : -1.0;
  m.sightings = static_cast<std::uint32_t>(b.sightings());
  m.refused = static_cast<std::uint32_t>(b.refused());
  picker.bias_pub.publish(m);

  if (!markers_pub_.hasSubscribers()) return;
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker arrow;
  arrow.header = m.header;
  arrow.ns = "gnss_bias/" + g.pickerId();
  arrow.id = 0;
  arrow.type = visualization_msgs::Marker::ARROW;
  arrow.action = used ? visualization_msgs::Marker::ADD : visualization_msgs::Marker::DELETE;
  arrow.pose.orientation.w = 1.0;
  arrow.scale.x = 0.1;  // shaft diameter
  arrow.scale.y = 0.25;
  arrow.scale.z = 0.3;
  arrow.color.r = 1.0;
  arrow.color.g = 0.5;
  arrow.color.a = 0.9;
  geometry_msgs::Point from, to;
  from.x = r.position.x();
  from.y = r.position.y();
  to.x = r.position.x() - bias.x();
  to.y = r.position.y() - bias.y();
  arrow.points = {from, to};
  markers.markers.push_back(arrow);
  visualization_msgs::Marker text = arrow;
  text.id = 1;
  text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
  text.action = visualization_msgs::Marker::ADD;
  text.points.clear();
  text.pose.position = from;
  text.pose.position.z = 1.5;
  text.scale.x = text.scale.y = 0;
  text.scale.z = 0.4;
  text.color.r = text.color.g = text.color.b = 1.0;
  char buf[160];
  if (used)
    std::snprintf(buf, sizeof buf, "%s bias %.1f m +-%.1f (%.0f s)", g.pickerId().c_str(), bias.norm(),
                  std::sqrt(0.5 * cov.trace()), m.sighting_age);
  else
    std::snprintf(buf, sizeof buf, "%s bias unknown", g.pickerId().c_str());
  text.text = buf;
  markers.markers.push_back(text);
  markers_pub_.publish(markers);
}

void GnssIngestNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const double now = ros::Time::now().toSec();
  std::size_t blackout = 0, rejected = 0;
  stat.add("fixes stamped in the future (rejected)", stamp_guard_.futureStamps());
  stat.add("clock jumps back", stamp_guard_.jumps());
  for (const auto& p : pickers_) {
    const sensors::GnssIngest& g = p->core->ingest;
    const sensors::GnssCounters& c = g.counters();
    const std::string k = g.pickerId() + " ";
    stat.add(k + "received", c.received);
    stat.add(k + "accepted", c.accepted);
    stat.add(k + "rejected no_fix/not_finite/negative_cov/out_of_order/jump/off_map",
             std::to_string(c.no_fix) + "/" + std::to_string(c.not_finite) + "/" + std::to_string(c.negative_covariance) +
                 "/" + std::to_string(c.out_of_order) + "/" + std::to_string(c.impossible_jump) + "/" +
                 std::to_string(c.off_map));
    stat.add(k + "blackouts (ended)", c.blackouts);
    stat.add(k + "longest blackout [s]", c.longest_blackout);
    const double age = g.ageOfLastFix(now);
    stat.add(k + "age of last fix [s]", std::isfinite(age) ? age : -1.0);
    if (g.inBlackout(now)) ++blackout;
    rejected += c.received - c.accepted;
  }
  stat.add("published", published_);
  stat.add("people received / identified / nobody's / malformed",
           std::to_string(fleet_->counters().people) + " / " + std::to_string(fleet_->counters().identified) +
               " / " + std::to_string(fleet_->counters().nobody) + " / " + std::to_string(bad_people_));
  stat.add("picker poses published / dropped", std::to_string(picker_poses_) + " / " + std::to_string(bad_poses_));
  stat.add("people messages refused (over max_people_per_message)", people_arrays_refused_);
  stat.add("beliefs dropped (future stamp, no valid mass)", bad_beliefs_);
  stat.add("pickers refused (bad GNSS topic)", pickers_refused_);
  stat.add("waiting for stamp order", ordering_.size());
  stat.add("ordering latency (s)", ordering_latency_);
  stat.add("pickers with GNSS", pickers_.size());
  stat.add("picker lists received", registry_updates_);
  for (const auto& p : pickers_) {
    const sensors::GnssIngest& g = p->core->ingest;
    const sensors::GnssBiasEstimator& b = g.bias();
    stat.add(g.pickerId() + " bias sightings accepted/refused",
             std::to_string(b.sightings()) + "/" + std::to_string(b.refused()));
    stat.add(g.pickerId() + " bias age [s]", b.sighted() ? now - b.lastSighting() : -1.0);
  }
  if (blackout > 0)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%zu picker(s) in GNSS blackout", blackout);
  else if (rejected > 0)
    stat.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "running; %zu fix(es) rejected so far", rejected);
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
  if (!pickers_.empty()) silence_.report(stat);
}

}  // namespace ros_adapter
}  // namespace picker_localisation
