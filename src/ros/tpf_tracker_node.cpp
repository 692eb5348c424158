#include "picker_localisation/ros/tpf_tracker_node.h"
#include "picker_localisation/tpf/tpf_tracker_node_options.h"

#include <picker_localisation/PickerList.h>
#include <std_msgs/String.h>
#include <boost/make_shared.hpp>
#include <ros/callback_queue.h>
#include <ros/names.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>

#include "picker_localisation/core/yaml_keys.h"
#include "picker_localisation/ros/fleet_topics.h"
#include "picker_localisation/ros/last_value_publisher.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/param_yaml.h"

namespace picker_localisation {
namespace ros_adapter {

YAML::Node tpfYamlFromRos(const ros::NodeHandle& pnh) {
  YAML::Node merged(YAML::NodeType::Map);
  const YAML::Node params = paramsAsYaml(pnh);
  std::string file;
  core::readOption(params, "tpf_tracker", "tpf_params_file", file);
  if (!file.empty()) {
    try {
      merged = YAML::LoadFile(file);
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(file + ": " + e.what());
    }
    if (!merged.IsMap()) merged = YAML::Node(YAML::NodeType::Map);
  }
  for (const auto& kv : params) merged[kv.first.as<std::string>()] = kv.second;
  return merged;
}

tpf::TpfParams tpfParamsWithOverrides(const YAML::Node& base, const std::string& overrides,
                                      std::vector<std::string>* unknown) {
  YAML::Node merged = YAML::Clone(base);
  if (!merged.IsMap()) merged = YAML::Node(YAML::NodeType::Map);
  if (overrides.size() > kMaxOverridesChars)
    throw std::runtime_error("tpf overrides: " + std::to_string(overrides.size()) +
                             " characters, more than " + std::to_string(kMaxOverridesChars));
  if (!overrides.empty()) {
    YAML::Node o;
    try {
      o = YAML::Load(overrides);
    } catch (const YAML::Exception& e) {
      throw std::runtime_error("tpf overrides: YAML syntax error: " + e.msg);
    }
    if (!o.IsNull() && !o.IsMap()) throw std::runtime_error("tpf overrides must be a YAML mapping of config/tpf.yaml keys");
    // Each key replaces the base's (a linear lookup): bounded, so a request cannot hold the tracker's only
    // spinner for seconds. A mapping of every key of config/tpf.yaml fits twice over.
    const std::size_t max_keys = 2 * tpf::TpfParams::yamlKeys().size();
    if (o.IsMap() && o.size() > max_keys)
      throw std::runtime_error("tpf overrides: " + std::to_string(o.size()) + " keys, more than " +
                               std::to_string(max_keys) + " (config/tpf.yaml has " +
                               std::to_string(tpf::TpfParams::yamlKeys().size()) + ")");
    if (o.IsMap()) {
      for (const auto& kv : o) merged[kv.first.as<std::string>()] = kv.second;
      // The same check as the file's keys at start-up: a typo is named, not silently ignored.
      if (unknown)
        for (auto& m : core::unknownKeys(o, tpf::TpfParams::yamlKeys(), "tpf overrides"))
          unknown->push_back(std::move(m));
    }
  }
  return tpf::TpfParams::fromYaml(merged);
}

struct TpfTracker::Track {
  tpf::TrackerFleet::Track* core = nullptr;
  const std::string& id() const { return core->id; }
  tpf::TopologicalParticleFilter& filter() const { return *core->filter; }
  LastValuePublisher<picker_localisation::PickerBelief> belief_pub;
  LastValuePublisher<geometry_msgs::PoseWithCovarianceStamped> estimate_pub;
  LastValuePublisher<std_msgs::String> current_node_pub;  // LCAS coordination's <agent>/current_node
  std::string current_node;                               // the last one published
  CountedPublisher markers_pub;
  ros::ServiceServer reset_srv, what_if_srv;
  std::uint64_t unknown_nodes = 0, what_if_calls = 0, last_reported_problems = 0;
  std::string belief_topic, estimate_topic, markers_topic, current_node_topic;  // resolved names ("": none)
};

TpfTracker::TpfTracker(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh), diagnostics_(nh, pnh) {
  tpf::TpfTrackerNodeOptions node_options;
  if (!loadOptionsAndPickers(pnh, node_options)) return;
  const std::string& pickers_file = node_options.fleet.pickers_file;
  const core::CommonNodeOptions& common = node_options.common;
  frame_id_ = common.map_frame;
  seed_param_ = node_options.seed;
  map_ = obtainMap(nh, common);
  if (!map_) return;  // obtainMap logged why
  fleet_ = std::make_unique<tpf::TrackerFleet>(map_, [this](tpf::TrackerFleet::Track& core) {
    const auto it = tracks_.find(core.id);
    if (it != tracks_.end()) publish(*it->second);
  });

  const std::string observations_topic = common.observations_topic;
  prefix_ = node_options.topic_prefix;
  // LCAS topological_navigation's coordination reads an agent's node from <agent>/current_node (std_msgs/String):
  // <current_node_namespace>/<id>/current_node, so "/" gives /<id>/current_node; "" publishes none.
  current_node_ns_ = node_options.currentNodeNamespace();
  ordering_latency_ = orderingLatency(common.ordering_latency, 0.5);
  stamp_guard_ = StampGuard(common.max_future_stamp);
  // Per-picker topics on demand above ~on_demand_topics_above pickers (see advertiseTopics).
  on_demand_.start(
      nh, node_options.fleet, registry_.size(), [this] { return tracks_.size(); },
      [this] {
        flush();
        for (auto& kv : tracks_) advertiseTopics(*kv.second);
      });
  ordering_ = core::StampOrderedBuffer<Pending>(ordering_latency_, 10000 + 20 * registry_.size());

  const std::vector<core::PickerConfig> initial = registry_.pickers();
  for (const core::PickerConfig& p : initial) {
    std::string error;
    std::vector<std::string> unknown;
    if (!startTrack(p, &error, &unknown)) {
      ROS_FATAL("tpf_tracker: picker %s: %s", p.id.c_str(), error.c_str());
      return;
    }
    for (const std::string& u : unknown) ROS_WARN("tpf_tracker: picker %s: %s", p.id.c_str(), u.c_str());
  }
  // The deployment's list (from a pickers file) is latched for gnss_ingest; one ~picker_id (tools, tests) names
  // no GNSS topic, so it publishes none.
  if (!pickers_file.empty()) {
    registry_pub_ = nh.advertise<picker_localisation::PickerList>(prefix_ + "/registry", 1, true);
    publishRegistry();
  }
  // The fleet stream: every flush's beliefs in one message, so a consumer of every picker costs one connection
  // and, under load, one message per burst.
  fleet_pub_ = CountedPublisher::advertise<picker_localisation::PickerBeliefArray>(nh, prefix_ + "/beliefs", 100);
  add_srv_ = pnh.advertiseService("add_picker", &TpfTracker::addPicker, this);
  remove_srv_ = pnh.advertiseService("remove_picker", &TpfTracker::removePicker, this);
  list_srv_ = pnh.advertiseService("list_pickers", &TpfTracker::listPickers, this);
  sub_ = nh.subscribe(observations_topic, 1000, &TpfTracker::observationCallback, this,
                      ros::TransportHints().tcpNoDelay());
  if (ordering_latency_ > 0.0)
    ordering_timer_ = nh.createTimer(ros::Duration(std::min(0.05, ordering_latency_ / 4.0)),
                                     &TpfTracker::orderingTick, this);
  updatePredictionTimer();
  diagnostics_.setHardwareID("tpf_tracker");
  diagnostics_.add("tpf_tracker", this, &TpfTracker::diagnoseFleet);
  diagnostics_.input("observations");
  diagnostics_.start(nh);
  map_follower_ =
      std::make_unique<MapFollower>(nh_, node_options.common, map_,
                                    [this](std::shared_ptr<const topology::TopologicalMap> m,
                                           const topology::MapChange& c) { adoptMap(std::move(m), c); });
  ROS_INFO("tpf_tracker: %zu picker(s), map '%s' (%zu nodes), ordering latency %.2f s (%s)", tracks_.size(),
           map_->name().c_str(), map_->numNodes(), ordering_latency_,
           ordering_latency_ > 0.0 ? "stamp-ordered replay" : "fused on arrival");
  ok_ = true;
}

// The node's options (its parameters over tpf_params_file's keys), the filters' base (the filter's keys of
// the same map) and the picker list. False after one FATAL line.
bool TpfTracker::loadOptionsAndPickers(const ros::NodeHandle& pnh, tpf::TpfTrackerNodeOptions& out) {
  try {
    const YAML::Node merged = tpfYamlFromRos(pnh);
    std::vector<std::string> messages;
    out = tpf::TpfTrackerNodeOptions::fromYaml(merged, &messages);
    for (const std::string& m : messages) ROS_WARN("%s", m.c_str());
    base_params_ = YAML::Clone(merged);
    for (const std::string& own : tpf::TpfTrackerNodeOptions::nodeKeys()) base_params_.remove(own);
  } catch (const std::exception& e) {
    ROS_FATAL("tpf_tracker: %s", e.what());
    return false;
  }
  const std::string& pickers_file = out.fleet.pickers_file;
  const std::string& single_id = out.picker_id;
  try {
    if (!pickers_file.empty()) {
      registry_ = core::PickerRegistry::load(pickers_file);
    } else if (!single_id.empty()) {
      core::PickerConfig one;
      one.id = single_id;
      registry_ = core::PickerRegistry({one}, "~picker_id");
    } else {
      ROS_FATAL("tpf_tracker: set ~pickers_file (config/pickers.yaml) or ~picker_id");
      return false;
    }
  } catch (const std::exception& e) {
    ROS_FATAL("tpf_tracker: %s", e.what());
    return false;
  }
  return true;
}

TpfTracker::~TpfTracker() { ros::getGlobalCallbackQueue()->removeByID(reinterpret_cast<std::uint64_t>(this)); }

bool TpfTracker::startTrack(const core::PickerConfig& picker, std::string* error,
                            std::vector<std::string>* unknown) {
  tpf::TpfParams params;
  try {
    params = tpfParamsWithOverrides(base_params_, picker.tpf_overrides, unknown);
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }
  const std::uint64_t seed =
      tpf::TrackerFleet::seedFor(picker.id, seed_param_ > 0 ? static_cast<std::uint64_t>(seed_param_) : 0);
  tpf::TrackerFleet::Track* core = fleet_->add(picker.id, params, seed, error);
  if (!core) return false;  // std::bad_alloc: this picker is refused, the others go on
  auto t = std::make_unique<Track>();
  Track* raw = t.get();
  t->core = core;
  const std::string base = prefix_ + "/" + picker.id;
  t->belief_topic = nh_.resolveName(base + "/belief");
  t->estimate_topic = nh_.resolveName(base + "/estimate");
  t->markers_topic = nh_.resolveName(base + "/markers");
  if (!current_node_ns_.empty())
    t->current_node_topic =
        nh_.resolveName((current_node_ns_ == "/" ? std::string() : current_node_ns_) + "/" + picker.id + "/current_node");
  advertiseTopics(*t);
  t->reset_srv = nh_.advertiseService<picker_localisation::ResetBelief::Request,
                                      picker_localisation::ResetBelief::Response>(
      base + "/reset", [this, raw](picker_localisation::ResetBelief::Request&,
                                   picker_localisation::ResetBelief::Response& res) {
        fleet_->reset(*raw->core);
        res.success = true;
        res.message = "belief of " + raw->id() + " forgotten; the next observation initialises it";
        flush();
        return true;
      });
  t->what_if_srv = nh_.advertiseService<picker_localisation::WhatIf::Request, picker_localisation::WhatIf::Response>(
      base + "/what_if", [this, raw](picker_localisation::WhatIf::Request& req, picker_localisation::WhatIf::Response& res) {
        ++raw->what_if_calls;
        const tpf::TopologicalParticleFilter& f = raw->filter();
        if (!(req.horizon >= 0.0 && req.horizon <= kMaxWhatIfHorizon)) {
          res.success = false;
          res.message =
              "horizon must be in [0, " + std::to_string(static_cast<int>(kMaxWhatIfHorizon)) + "] s";
          ROS_WARN_THROTTLE(5.0, "tpf_tracker %s: what_if refused: %s", raw->id().c_str(),
                            res.message.c_str());
          return true;
        }
        tpf::Belief b;
        if (req.with_observation) {
          tpf::UpdateResult r;
          if (req.observation.nodes.size() > map_->numNodes()) {
            res.success = false;
            res.message = "hypothetical observation has more nodes than the map";
            return true;
          }
          b = f.posteriorUnder(fromMsg(req.observation, *map_), req.horizon, req.seed, &r);
          if (!r.ok()) {
            res.success = false;
            res.message = std::string("hypothetical observation ") + tpf::toString(r.status) + ": " + r.reason;
            res.belief = toBeliefMsg(b, *map_, raw->id(), frame_id_);
            return true;
          }
        } else {
          if (!f.initialised()) {
            res.success = false;
            res.message = "no belief yet: " + raw->id() + " has received no observation";
            res.belief = toBeliefMsg(f.belief(), *map_, raw->id(), frame_id_);
            return true;
          }
          b = f.predictAhead(req.horizon, req.seed);
        }
        res.success = true;
        res.belief = toBeliefMsg(b, *map_, raw->id(), frame_id_);
        return true;
      });
  diagnostics_.add("tpf_tracker " + picker.id,
                   [this, raw](diagnostic_updater::DiagnosticStatusWrapper& stat) { diagnose(*raw, stat); });
  tracks_[picker.id] = std::move(t);
  publish(*raw);  // "waiting for the first observation": the topic exists from the start
  flush();
  ROS_INFO("tpf_tracker %s: %zu particles, method %s motion, prediction every %.1f s", picker.id.c_str(),
           params.num_particles, tpf::toString(params.motion_model), core->prediction_period);
  return true;
}

void TpfTracker::advertiseTopics(Track& t) {
  // Few pickers: every topic always. A farm's worth: each while someone subscribes (the master polled).
  const TopicDemand* demand = on_demand_.demand();
  Track* raw = &t;
  advertiseWhileWanted(t.belief_pub, t.belief_topic, demand, [&] { t.belief_pub.advertise(nh_, t.belief_topic, 10); });
  advertiseWhileWanted(t.estimate_pub, t.estimate_topic, demand,
                       [&] { t.estimate_pub.advertise(nh_, t.estimate_topic, 10); });
  if (!t.current_node_topic.empty())
    advertiseWhileWanted(t.current_node_pub, t.current_node_topic, demand,
                         [&] { t.current_node_pub.advertise(nh_, t.current_node_topic, 2); });
  // Markers are built only for a subscriber (rviz); a new one gets the current markers at once.
  advertiseWhileWanted(t.markers_pub, t.markers_topic, demand, [&] {
    t.markers_pub = CountedPublisher::advertise<visualization_msgs::MarkerArray>(
        nh_, t.markers_topic, 2, [this, raw](const ros::SingleSubscriberPublisher& s) {
          s.publish(toMarkers(raw->filter().belief(), *map_, raw->id(), frame_id_));
        });
  });
}

void TpfTracker::updatePredictionTimer() {
  // One timer for every picker, ticking at 4x the fastest prediction rate so a prediction happens within a
  // quarter period of falling due.
  const double fastest = fleet_->fastestPredictionPeriod();
  if (fastest <= 0.0) {  // no picker predicts periodically: no timer
    prediction_timer_.stop();
    prediction_timer_ = ros::Timer();
    timer_period_ = 0.0;
    return;
  }
  if (fastest / 4.0 == timer_period_) return;
  timer_period_ = fastest / 4.0;
  prediction_timer_ = nh_.createTimer(ros::Duration(timer_period_), &TpfTracker::predictionTick, this);
}

std::vector<TpfTracker::Track*> TpfTracker::route(bool identifying, const std::string& picker_id,
                                                  const std::vector<std::string>& candidates) {
  std::vector<Track*> out;
  for (tpf::TrackerFleet::Track* core : fleet_->route(identifying, picker_id, candidates))
    out.push_back(tracks_.at(core->id).get());
  return out;
}

void TpfTracker::observationCallback(const picker_localisation::Observation::ConstPtr& msg) {
  diagnostics_.tick("observations");
  ++received_;
  checkClockJump();
  const std::vector<Track*> targets = route(msg->identifying, msg->picker_id, msg->candidate_pickers);
  if (targets.empty()) {
    ++unrouted_;  // a picker this node does not track
    return;
  }
  if (stamp_guard_.tooFarInFuture(msg->header.stamp)) {
    // Adopting it would make every later observation "too old" and start ~(stamp - now) / period predictions.
    ROS_WARN_THROTTLE(5.0, "tpf_tracker: %s observation for %s stamped %.3f is more than %.1f s ahead of the clock: dropped",
                      msg->sensor.c_str(), msg->identifying ? msg->picker_id.c_str() : "anyone",
                      msg->header.stamp.toSec(), stamp_guard_.maxFuture());
    return;
  }
  if (msg->nodes.size() > map_->numNodes() || msg->likelihood.size() > map_->numNodes()) {
    // A likelihood names each node at most once: a longer one is not an observation of this map.
    ++oversized_;
    ROS_WARN_THROTTLE(5.0, "tpf_tracker: %s observation with %zu nodes dropped: the map has %zu",
                      core::clippedForLog(msg->sensor).c_str(), msg->nodes.size(), map_->numNodes());
    return;
  }
  std::size_t unknown = 0;
  Pending p{fromMsg(*msg, *map_, &unknown), msg->sensor};  // decoded once, whoever it concerns
  for (Track* t : targets) t->unknown_nodes += unknown;
  if (unknown > 0)
    ROS_WARN_THROTTLE(5.0, "tpf_tracker: %zu node name(s) of a %s observation are not in the map (skipped)", unknown,
                      msg->sensor.c_str());
  if (ordering_latency_ <= 0.0) {
    for (Track* t : targets) report(fleet_->process(*t->core, p.obs), p.sensor);
    flushWhenIdle();
    return;
  }
  // Tie-break equal stamps by content so the fusion order never depends on arrival order.
  std::string key = msg->sensor + "|" + msg->robot_id + "|" + msg->picker_id + "|";
  for (std::size_t i = 0; i < msg->nodes.size() && i < msg->likelihood.size(); ++i)
    key += msg->nodes[i] + ":" + std::to_string(msg->likelihood[i]) + ",";
  ordering_.push(p.obs.stamp, key, std::move(p));
}

void TpfTracker::dispatch(const Pending& p) {
  // Routed again on release: a picker may have been added or removed while the observation waited.
  for (const tpf::TrackerFleet::Outcome& o : fleet_->process(p.obs)) report(o, p.sensor);
}

void TpfTracker::report(const tpf::TrackerFleet::Outcome& o, const std::string& sensor) {
  const tpf::TrackerFleet::Track& t = *o.track;
  if (o.exception) {
    // Nothing a callback meets may stop the node (roscpp would end the process, and roslaunch the robot): the
    // fleet forgot the picker's belief, the next observation initialises it again.
    ROS_ERROR_THROTTLE(5.0, "tpf_tracker %s: %s; belief reset", t.id.c_str(), t.last_problem.c_str());
  } else if (!o.result.ok() && o.result.status != tpf::UpdateStatus::kIgnoredSensor) {
    ROS_WARN_THROTTLE(5.0, "tpf_tracker %s: %s observation %s", t.id.c_str(), sensor.c_str(),
                      t.last_problem.c_str());
  } else if (o.result.reinitialised) {
    ROS_INFO_THROTTLE(5.0, "tpf_tracker %s: re-initialised (JSD %.3f)", t.id.c_str(), t.filter->belief().jsd);
  }
}

void TpfTracker::checkClockJump() {
  if (!stamp_guard_.clockJumpedBack()) return;
  ROS_WARN("tpf_tracker: the clock jumped back: %zu belief(s) reset, %zu waiting observation(s) dropped",
           tracks_.size(), ordering_.size());
  ordering_.clear();
  fleet_->resetAll();
  flush();
}

void TpfTracker::adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                          const topology::MapChange& change) {
  flush();  // the queued messages name nodes of the old map
  const std::size_t dropped = ordering_.size();
  ordering_.clear();  // decoded on the old map's node indices
  map_ = std::move(map);
  // current_node is sent when its name changed (renamed, removed)
  for (const std::string& id : fleet_->adoptMap(map_, change.old_to_new))
    ROS_ERROR("tpf_tracker %s: %s; starting afresh", id.c_str(), fleet_->find(id)->last_problem.c_str());
  flush();
  ++map_updates_;
  if (dropped > 0)
    ROS_WARN("tpf_tracker: %zu observation(s) waiting for stamp order dropped with the old map", dropped);
}

void TpfTracker::orderingTick(const ros::TimerEvent&) {
  checkClockJump();
  const double now = ros::Time::now().toSec();
  if (now <= 0.0) return;
  for (auto& item : ordering_.release(now)) dispatch(item.second);
  flush();
}

void TpfTracker::predictionTick(const ros::TimerEvent&) {
  checkClockJump();
  const double now = ros::Time::now().toSec();
  if (now <= 0.0) return;  // sim clock not running yet
  // Predictions wait for the ordering latency too, so none overtakes an observation still in the buffer.
  fleet_->predictDue(now - ordering_latency_);
  flush();
}

void TpfTracker::publish(Track& t) {
  // Queued, sent by flush(): messages published back to back cost roscpp's poll thread one walk over every
  // publication of the process, not one walk each.
  const tpf::Belief& b = t.filter().belief();
  Outgoing out{&t, toBeliefMsg(b, *map_, t.id(), frame_id_), std::nullopt, std::nullopt, std::nullopt};
  if (b.initialised) out.estimate = toEstimateMsg(b, *map_, frame_id_);
  if (b.initialised && !t.current_node_topic.empty() && map_->node(b.map_node).name != t.current_node) {
    t.current_node = map_->node(b.map_node).name;  // sent on change, latched (as LCAS agents do)
    std_msgs::String node;
    node.data = t.current_node;
    out.current_node = node;
  }
  if (t.markers_pub.hasSubscribers()) out.markers = toMarkers(b, *map_, t.id(), frame_id_);
  outgoing_.push_back(std::move(out));
}

void TpfTracker::flush() {
  if (outgoing_.empty()) return;
  picker_localisation::PickerBeliefArray fleet;
  const bool to_fleet = fleet_pub_.hasSubscribers();
  for (Outgoing& o : outgoing_) {
    if (to_fleet) fleet.beliefs.push_back(o.belief);
    o.track->belief_pub.publish(std::move(o.belief));
    if (o.estimate) o.track->estimate_pub.publish(std::move(*o.estimate));
    if (o.current_node) o.track->current_node_pub.publish(std::move(*o.current_node));
    if (o.markers) o.track->markers_pub.publish(*o.markers);
  }
  outgoing_.clear();
  if (to_fleet) {
    fleet.header.stamp = fleet.beliefs.back().header.stamp;
    fleet_pub_.publish(fleet);
  }
}

namespace {
// Runs TpfTracker::flush() once the callbacks queued before it have run.
class FlushCallback : public ros::CallbackInterface {
 public:
  explicit FlushCallback(std::function<void()> f) : f_(std::move(f)) {}
  CallResult call() override {
    f_();
    return Success;
  }

 private:
  std::function<void()> f_;
};
}  // namespace

void TpfTracker::flushWhenIdle() {
  // The beliefs go out once the messages already waiting in the callback queue are fused (no added latency
  // when none waits; one burst under load), or at once after 64.
  if (outgoing_.empty()) return;
  if (outgoing_.size() >= 64) {
    flush();
    return;
  }
  if (flush_scheduled_) return;
  flush_scheduled_ = true;
  ros::getGlobalCallbackQueue()->addCallback(boost::make_shared<FlushCallback>([this] {
    flush_scheduled_ = false;
    flush();
  }), reinterpret_cast<std::uint64_t>(this));
}

void TpfTracker::publishRegistry() {
  if (!registry_pub_) return;
  picker_localisation::PickerList m;
  m.header.stamp = ros::Time::now();
  for (const core::PickerConfig& p : registry_.pickers()) m.pickers.push_back(toMsg(p));
  registry_pub_.publish(m);
}

bool TpfTracker::addPicker(picker_localisation::AddPicker::Request& req, picker_localisation::AddPicker::Response& res) {
  core::PickerConfig p = fromMsg(req.picker);
  p.tpf_overrides = req.tpf_overrides;
  std::string error = gnssTopicProblem(p.gnss_topic);
  std::vector<std::string> unknown;
  core::PickerRegistry updated = registry_;
  if (error.empty()) {
    try {
      updated.add(p);  // id rules, duplicates, tags or a GNSS topic worn by another picker
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (error.empty()) startTrack(p, &error, &unknown);
  res.success = error.empty();
  if (!res.success) {
    ++refused_requests_;
    res.message = "picker '" + core::clippedForLog(p.id) + "' not added: " + error;
    ROS_WARN("tpf_tracker: %s", res.message.c_str());
    return true;
  }
  registry_ = updated;
  ++added_;
  updatePredictionTimer();
  publishRegistry();
  res.message = "tracking " + p.id + " (" + std::to_string(tracks_.size()) + " picker(s))";
  for (const std::string& u : unknown) res.message += "; ignored " + u;
  if (unknown.empty())
    ROS_INFO("tpf_tracker: %s", res.message.c_str());
  else
    ROS_WARN("tpf_tracker: %s", res.message.c_str());
  return true;
}

bool TpfTracker::removePicker(picker_localisation::RemovePicker::Request& req,
                              picker_localisation::RemovePicker::Response& res) {
  const auto it = tracks_.find(req.id);
  if (it == tracks_.end()) {
    ++refused_requests_;
    res.success = false;
    res.message = "no picker '" + core::clippedForLog(req.id) + "' is tracked (list_pickers names them)";
    ROS_WARN("tpf_tracker: remove_picker refused: %s", res.message.c_str());
    return true;
  }
  flush();  // nothing queued may outlive its track
  // rviz keeps the last markers of a topic that goes away: delete them first.
  visualization_msgs::MarkerArray gone = toMarkers(tpf::Belief{}, *map_, req.id, frame_id_);
  for (auto& m : gone.markers) m.action = visualization_msgs::Marker::DELETE;
  it->second->markers_pub.publish(gone);
  diagnostics_.removeByName("tpf_tracker " + req.id);
  tracks_.erase(it);  // its publishers and services go with it
  fleet_->remove(req.id);
  registry_.remove(req.id);
  ++removed_;
  updatePredictionTimer();  // a fast picker gone: the timer slows down (or stops) with it
  publishRegistry();
  res.success = true;
  res.message = "stopped tracking " + req.id + " (" + std::to_string(tracks_.size()) + " picker(s) left)";
  ROS_INFO("tpf_tracker: %s", res.message.c_str());
  return true;
}

bool TpfTracker::listPickers(picker_localisation::ListPickers::Request&, picker_localisation::ListPickers::Response& res) {
  for (const core::PickerConfig& p : registry_.pickers()) res.pickers.push_back(toMsg(p));
  return true;
}

void TpfTracker::diagnoseFleet(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  stat.add("pickers", tracks_.size());
  std::size_t advertised = 0;
  for (const auto& kv : tracks_)
    advertised += kv.second->belief_pub.advertised() + kv.second->estimate_pub.advertised() +
                  kv.second->markers_pub.advertised() + kv.second->current_node_pub.advertised();
  stat.add("per-picker topics advertised", advertised);
  stat.add("per-picker topics on demand", on_demand_.onDemand() ? "yes" : "no");
  stat.add("observations received", received_);
  stat.add("observations for no tracked picker", unrouted_);
  stat.add("observations with more nodes than the map (dropped)", oversized_);
  stat.add(
      "map updates adopted / map messages refused",
      std::to_string(map_updates_) + " / " + std::to_string(map_follower_ ? map_follower_->refusals() : 0));
  stat.add("observations stamped in the future (dropped)", stamp_guard_.futureStamps());
  stat.add("clock jumps back (beliefs reset)", stamp_guard_.jumps());
  stat.add("ordering latency (s)", ordering_latency_);
  stat.add("observations waiting for stamp order", ordering_.size());
  stat.add("ordering overflows", ordering_.forcedReleases());
  stat.add("pickers added / removed / requests refused",
           std::to_string(added_) + " / " + std::to_string(removed_) + " / " + std::to_string(refused_requests_));
  stat.summaryf(diagnostic_msgs::DiagnosticStatus::OK, "tracking %zu picker(s)", tracks_.size());
}

void TpfTracker::diagnose(Track& t, diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const tpf::TrackerFleet::Track& core = *t.core;
  const auto& c = core.filter->counters();
  const std::uint64_t problems = c.rejected_invalid + c.dropped_too_old + core.exceptions;
  stat.hardware_id = core.id;
  stat.add("picker_id", core.id);
  stat.add("observations received", core.received);
  stat.add("observations stamped in the future (dropped)", stamp_guard_.futureStamps());
  stat.add("accepted", c.accepted);
  stat.add("reordered (late, within window)", c.reordered);
  stat.add("dropped (too old)", c.dropped_too_old);
  stat.add("rejected (invalid)", c.rejected_invalid);
  stat.add("ignored (sensor not fused in this mode)", c.ignored_sensor);
  stat.add("unknown node names skipped", t.unknown_nodes);
  stat.add("exceptions caught (belief reset)", core.exceptions);
  stat.add("re-initialisations", c.reinitialisations);
  stat.add("no-overlap updates", c.no_overlap);
  stat.add("unidentified people taken for someone else", c.someone_else);
  stat.add("reported rows that moved particles across", c.lane_evidence_projections);
  stat.add("predictions", c.predictions);
  stat.add("what-if calls", t.what_if_calls);
  stat.add("resets", core.resets);
  const auto& b = core.filter->belief();
  stat.add("entropy (nats)", b.entropy);
  stat.add("jsd", b.jsd);
  stat.add("p_rj", b.unconnected_jump_probability);
  if (b.initialised && b.map_node < map_->numNodes()) stat.add("estimated node", map_->node(b.map_node).name);
  if (problems > t.last_reported_problems) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, core.last_problem);
  } else if (!b.initialised) {
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "waiting for the first observation");
  } else {
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  }
  t.last_reported_problems = problems;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
