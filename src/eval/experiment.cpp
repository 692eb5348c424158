#include "picker_localisation/eval/experiment.h"
#include "picker_localisation/nbs/nbs_planner_node_options.h"
#include "picker_localisation/sensors_ranging/ranging_node_options.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <mutex>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/core/yaml_keys.h"
#include "picker_localisation/eval/ukf_metric_tracker.h"
#include "picker_localisation/topology/map_io.h"

#include <yaml-cpp/yaml.h>

#include "picker_localisation/dispatch/call_dispatcher.h"
#include "picker_localisation/dispatch/call_input.h"
#include "picker_localisation/dispatch/dispatcher_node_options.h"
#include "picker_localisation/nbs/next_best_sense_planner.h"
#include "picker_localisation/nbs/tpf_belief_source.h"
#include "picker_localisation/sensors_ranging/gnss_fleet.h"
#include "picker_localisation/sensors_ranging/rfid_observation_model.h"
#include "picker_localisation/sensors_vision/leg_pipeline.h"
#include "picker_localisation/sim/farm_simulator.h"
#include "picker_localisation/tpf/tracker_fleet.h"

#ifndef PL_EVAL_PACKAGE_DIR
#define PL_EVAL_PACKAGE_DIR "."
#endif

namespace picker_localisation {
namespace eval {

namespace fs = std::filesystem;
using topology::NodeIndex;

Scenario parseScenario(const std::string& name) {
  if (name == "single") return Scenario::kSingle;
  if (name == "navigation") return Scenario::kNavigation;
  if (name == "multi") return Scenario::kMulti;
  if (name == "calls") return Scenario::kCalls;
  throw std::invalid_argument("unknown scenario '" + name +
                              "' (expected single, navigation, multi or calls)");
}

const char* toString(Scenario s) {
  switch (s) {
    case Scenario::kSingle:
      return "single";
    case Scenario::kNavigation:
      return "navigation";
    case Scenario::kMulti:
      return "multi";
    case Scenario::kCalls:
      return "calls";
  }
  return "?";
}

namespace {

enum class Tracker { kTpf, kUkf, kRawFix, kOracle };
enum class RobotPolicy { kPatrol, kEstimatedNode, kNbs };

// What a method is made of. The TPF preset names are TpfParams::presetForMethod's.
struct MethodSpec {
  std::string name;
  Tracker tracker = Tracker::kTpf;
  std::string tpf_preset = "tpf";
  bool gnss = true, lidar = false, rfid = false;
  RobotPolicy policy = RobotPolicy::kPatrol;
};

const std::vector<MethodSpec>& methodSpecs() {
  static const std::vector<MethodSpec> specs = {
      {"khan_connected", Tracker::kTpf, "khan_connected", true, false, false, RobotPolicy::kPatrol},
      {"khan_unconnected", Tracker::kTpf, "khan_unconnected", true, false, false, RobotPolicy::kPatrol},
      // Not in Table II: the node nearest the latest accepted fix (no filter; Khan et al. Fig. 3c's
      // reference), and the full TPF on GNSS alone.
      {"raw_fix", Tracker::kRawFix, "", true, false, false, RobotPolicy::kPatrol},
      {"gnss_tpf", Tracker::kTpf, "tpf", true, false, false, RobotPolicy::kPatrol},
      {"lidar_gnss", Tracker::kTpf, "tpf", true, true, false, RobotPolicy::kPatrol},
      {"rfid_gnss", Tracker::kTpf, "tpf", true, false, true, RobotPolicy::kPatrol},
      {"rfid_lidar_gnss", Tracker::kTpf, "tpf", true, true, true, RobotPolicy::kPatrol},
      {"estimated_node", Tracker::kTpf, "tpf", true, true, true, RobotPolicy::kEstimatedNode},
      {"nbs", Tracker::kTpf, "tpf", true, true, true, RobotPolicy::kNbs},
      {"ukf_metric", Tracker::kUkf, "", true, true, false, RobotPolicy::kPatrol},
      {"no_monitor", Tracker::kTpf, "no_monitor", true, true, true, RobotPolicy::kPatrol},
      {"constant_speed", Tracker::kTpf, "constant_speed", true, true, true, RobotPolicy::kPatrol},
      // Calls scenario: the dispatcher told the node the picker stands on (the limit of any estimate).
      {"oracle", Tracker::kOracle, "", true, false, false, RobotPolicy::kPatrol},
  };
  return specs;
}

const MethodSpec& specOf(const std::string& method) {
  for (const auto& s : methodSpecs())
    if (s.name == method) return s;
  throw std::invalid_argument("unknown method '" + method + "'");
}

std::string legModelPath(const RunConfig& config) {
  return config.leg_model.empty() ? std::string(PL_EVAL_PACKAGE_DIR) + "/config/leg_classifier.yml"
                                  : config.leg_model;
}

std::size_t numPickers(const RunConfig& config) {
  if (config.scenario == Scenario::kCalls) return config.pickers;
  return config.scenario == Scenario::kMulti ? 3 : 1;
}

}  // namespace

std::string resolveConfigFile(const std::string& value, const std::string& package_file) {
  if (value == "none") return "";
  if (!value.empty()) return value;
  const std::string p = std::string(PL_EVAL_PACKAGE_DIR) + "/config/" + package_file;
  return fs::exists(p) ? p : "";
}

// The leg_detector node's options from the `leg_detector:` section of config/vision.yaml and, as demo.launch
// loads it after that file, the simulated-laser overlay config/vision_sim.yaml (leg_threshold 0.42, 0.3 at
// its 0.5 deg: the classifier was trained on real scans, see docs/readme/sensors_vision.md). Later files
// override earlier ones.
std::vector<std::string> visionConfigFiles(const std::string& value) {
  std::vector<std::string> files;
  if (value == "none") return files;
  if (value.empty()) {
    for (const char* f : {"vision.yaml", "vision_sim.yaml"}) {
      const std::string p = resolveConfigFile("", f);
      if (!p.empty()) files.push_back(p);
    }
    return files;
  }
  std::stringstream ss(value);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) files.push_back(item);
  return files;
}

const std::vector<std::string>& allMethodNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& s : methodSpecs()) n.push_back(s.name);
    return n;
  }();
  return names;
}

bool isKnownMethod(const std::string& method) {
  const auto& n = allMethodNames();
  return std::find(n.begin(), n.end(), method) != n.end();
}

std::vector<std::string> defaultMethods(Scenario s) {
  switch (s) {
    case Scenario::kSingle:
      return {"khan_unconnected", "khan_connected", "lidar_gnss", "rfid_gnss", "rfid_lidar_gnss"};
    case Scenario::kNavigation:
      return {"estimated_node", "nbs"};
    case Scenario::kMulti:
      return {"ukf_metric", "rfid_lidar_gnss", "no_monitor", "constant_speed"};
    case Scenario::kCalls:
      return {"oracle", "raw_fix", "khan_connected", "estimated_node", "nbs"};
  }
  return {};
}

std::string methodUnavailableReason(const std::string& method, const RunConfig& config) {
  if (!isKnownMethod(method)) return "unknown method";
  const MethodSpec& spec = specOf(method);
  std::vector<std::string> missing;
  if (spec.lidar && !fs::exists(legModelPath(config)))
    missing.push_back("the leg classifier model " + legModelPath(config));
  if (missing.empty()) return "";
  std::string reason = "needs ";
  for (std::size_t i = 0; i < missing.size(); ++i) reason += (i ? ", " : "") + missing[i];
  return reason;
}

namespace {

// The front-ends' options: the same files and the same schema as the gnss_ingest / rfid_ranging nodes.
sensors::GnssIngestOptions gnssOptions(const std::string& file) {
  return file.empty() ? sensors::GnssIngestOptions() : sensors::GnssIngestOptions::fromYamlFile(file);
}
sensors::RfidModelOptions rfidOptions(const std::string& file) {
  return file.empty() ? sensors::RfidModelOptions() : sensors::RfidModelOptions::fromYamlFile(file);
}

// The simulator of a run: the ROS graph's configuration files, then the scenario's pickers, one robot
// patrolling the lanes and only the sensors the method uses (the simulator guarantees that switching a sensor
// off changes neither the pickers' walks nor their GNSS errors, so every method of a seed sees the same
// pickers).
sim::SimConfig simConfigFor(const RunConfig& config, const MethodSpec& spec) {
  const std::string sim_file = resolveConfigFile(config.sim_config, "sim.yaml");
  const std::string datum_file = resolveConfigFile(config.datum_file, "datum.yaml");
  const std::string pickers_file = resolveConfigFile(config.pickers_file, "pickers.yaml");
  sim::SimConfig sc = sim_file.empty() ? sim::SimConfig() : sim::loadSimConfig(sim_file);
  if (!datum_file.empty()) sc.datum = core::GeodeticDatum::load(datum_file).config();
  sc.seed = config.seed;
  const std::size_t n = numPickers(config);
  sc.pickers.clear();
  if (!pickers_file.empty()) {
    const auto specs = sim::pickerSpecsFromRegistry(core::PickerRegistry::load(pickers_file));
    if (specs.size() < n && config.scenario != Scenario::kCalls)
      throw std::runtime_error(pickers_file + ": scenario " + toString(config.scenario) + " needs " +
                               std::to_string(n) + " pickers");
    sc.pickers.assign(specs.begin(), specs.begin() + static_cast<long>(std::min(n, specs.size())));
  }
  if (sc.pickers.size() < n) {  // the calls scenario's farm: the file's pickers, then picker_<i> with tags
    for (std::size_t i = sc.pickers.size(); i < n; ++i) {
      sim::PickerSpec p;
      p.id = "picker_" + std::to_string(i + 1);
      p.rfid_tag = "rfid_000" + std::to_string(i + 1);
      p.uwb_tag = "uwb_000" + std::to_string(i + 1);
      sc.pickers.push_back(p);
    }
  }
  sc.num_robots = 1;
  sc.robot_ids.clear();
  sc.robot_motion.patrol = sim::PatrolPolicy::kLanes;
  sc.enable.gnss = spec.gnss;
  sc.enable.laser = spec.lidar;
  sc.enable.rfid = spec.rfid;
  if (config.scenario == Scenario::kCalls) {
    // Robots wait where they are until the dispatcher sends them; every robot reads RFID tags (arrival).
    sc.num_robots = config.robots;
    sc.robot_motion.patrol = sim::PatrolPolicy::kStay;
    sc.calls.enabled = true;
    sc.enable.rfid = true;
    sc.enable.laser = true;  // every robot has its lasers; the method decides what its belief uses
  }
  sc.enable.uwb = false;
  sc.enable.camera = false;
  return sc;
}

// One run's graph: the nodes' own core classes, wired as the ROS graph wires the nodes. gnss_ingest is a
// sensors::GnssFleet, rfid_ranging an RfidObservationModel, leg_detector a LegPipeline, tpf_tracker a
// tpf::TrackerFleet, nbs_planner a NextBestSensePlanner; publish() is the /observations topic (every tracker
// and gnss_ingest's identifying-observation input), the tracker fleet's belief listener the beliefs topic
// gnss_ingest follows. Only the scoring (ground truth) is the runner's own.
class GraphRun {
 public:
  GraphRun(std::shared_ptr<const topology::TopologicalMap> map, const RunConfig& config);
  sim::FarmSimulator& simulator() { return simulator_; }
  void onFix(const sim::GnssFixWithTruth& fix);
  void onRfid(const sim::RfidReadingWithTruth& read);
  void onScan(const sim::LaserScanWithTruth& scan);
  void onCall(const sim::PickerCall& call);
  // The trackers' periodic predictions and the planner, at the end of a simulator step.
  void endOfStep(double now);
  // One error sample per picker with an estimate (scoring).
  void sample(double t);
  // The calls scenario's calls still open at the end of the run: scored as not arrived.
  void finish(double now);  // the run ended at now: open calls are scored as they stand
  RunResult& result() { return result_; }

 private:
  // What a picker's run is scored on; never reaches an estimator.
  struct Scoring {
    std::string id;
    NodeIndex raw_fix_node = topology::kInvalidNode;  // raw_fix: the node nearest the latest accepted fix
    Eigen::Vector2d true_gnss_error{std::nan(""), std::nan("")};  // the simulator's error of the latest fix
    // "Lane right within 30 s of a sighting after the first fix or a blackout".
    double restart = std::nan("");             // stamp of the first fix, or of the fix that ended a blackout
    double seen_after_restart = std::nan("");  // first accepted bias sighting after it
    // The latest accepted LiDAR bias sighting: its stamp, and how far the person was from this picker then.
    double lidar_sighting_stamp = std::nan("");
    double lidar_sighting_error = std::nan("");
  };
  // A call the dispatcher serves, scored from the simulator's truth.
  struct OpenCall {
    std::size_t picker = 0;
    CallRecord record;
    bool arrived = false, released = false;
    std::size_t robot = 0;
    NodeIndex robot_node = topology::kInvalidNode;   // the serving robot's current node at the last step
    topology::LaneIndex inside = topology::kNoLane;  // the lane whose inner edge it drives along, if any
    Eigen::Vector2d robot_at = Eigen::Vector2d::Zero();
  };
  // Scoring: the belief and bias estimate of a call's picker when its robot is assigned.
  void recordCallPicker(OpenCall& c, double now);
  // How long the call waited for a robot and how long that robot waited at a lane end (scoring).
  void recordWaits(CallRecord& r, const dispatch::Call& call, double now);
  void publish(const core::Observation& obs);
  NodeIndex estimate(std::size_t picker) const;
  // Scoring an arrival; `evidence`: the person's association probability (lidar) or the read's RSSI (rfid).
  void arrived(std::uint64_t call_id, std::size_t robot, double stamp, const char* by, double evidence);
  // The calls scenario at the end of a step: beliefs and robot nodes to the dispatcher, its goals to the
  // robots, loaded pickers released, each open call scored.
  void dispatchCalls(double now);
  // The calls scenario's robots serving no call, positioned by the planner as nbs_planner positions them:
  // each plans every planning_period (and at once when its call ended) with the other robots' goals as
  // claims.
  void positionIdleRobots(double now);
  // The planner's views of the pickers, with the bias covariance gnss_ingest publishes at `now`.
  std::vector<nbs::BeliefSource*> views();
  // The planner of config/nbs.yaml (planning_period, battery_level, what_if_seed as the node reads them) with
  // `policy`, and a what-if view of every picker's filter.
  void makePlanner(nbs::Policy policy);

  std::shared_ptr<const topology::TopologicalMap> map_;
  RunConfig config_;
  const MethodSpec& spec_;
  sim::FarmSimulator simulator_;
  std::vector<Scoring> scoring_;
  std::vector<std::vector<double>> wrong_identity_stamps_;  // scoring: per picker, its wrong identities
  std::unique_ptr<sensors::GnssFleet> gnss_;
  std::unique_ptr<sensors::RfidObservationModel> rfid_;
  std::unique_ptr<vision::LegPipeline> legs_;
  std::unique_ptr<tpf::TrackerFleet> trackers_;           // Tracker::kTpf
  UkfMetricTracker ukf_;                                  // Tracker::kUkf
  std::unique_ptr<dispatch::CallDispatcher> dispatcher_;  // Scenario::kCalls
  dispatch::DispatcherNodeOptions dispatcher_options_;
  std::map<std::uint64_t, OpenCall> open_calls_;
  std::unique_ptr<nbs::NextBestSensePlanner> planner_;
  std::vector<std::unique_ptr<nbs::TpfBeliefSource>> sources_;
  double replan_period_ = 0.0, battery_level_ = 1.0, last_plan_ = -1e300;
  struct IdleRobot {
    double last_plan = -1e300;
    bool serving = false;  // served a call at the last step
    nbs::Claim goal;       // the planner's last goal (node kInvalidNode: none)
  };
  std::vector<IdleRobot> idle_;  // calls scenario with idle_robots "nbs", per robot
  std::unique_ptr<nbs::TrayClock> tray_clock_;  // calls scenario: the pickers' call-due weights
  RunResult result_;
};

GraphRun::GraphRun(std::shared_ptr<const topology::TopologicalMap> map, const RunConfig& config)
    : map_(std::move(map)),
      config_(config),
      spec_(specOf(config.method)),
      simulator_(*map_, simConfigFor(config, spec_)),
      replan_period_(config.replan_period) {
  const std::size_t n = simulator_.numPickers();
  std::vector<core::PickerConfig> registry_entries;
  gnss_ = std::make_unique<sensors::GnssFleet>(
      map_, simulator_.datum(), gnssOptions(resolveConfigFile(config.gnss_config, "gnss_ingest.yaml")));
  for (std::size_t i = 0; i < n; ++i) {
    const sim::PickerSpec& ps = simulator_.pickerSpec(i);
    scoring_.push_back({ps.id});
    wrong_identity_stamps_.emplace_back();
    gnss_->add(ps.id);
    registry_entries.push_back({ps.id, "", {ps.rfid_tag}, ps.uwb_tag, ""});
  }
  rfid_ = std::make_unique<sensors::RfidObservationModel>(
      core::PickerRegistry(registry_entries), map_,
      rfidOptions(resolveConfigFile(config.rfid_config, "rfid_ranging.yaml")));
  if (spec_.lidar || config.scenario == Scenario::kCalls) {  // leg_detector's pipeline, same files and keys
    auto classifier = std::make_shared<vision::LegClassifier>();
    classifier->load(legModelPath(config));
    legs_ = std::make_unique<vision::LegPipeline>(
        classifier, vision::LegPipelineOptions::fromYamlFiles(visionConfigFiles(config.vision_config)));
  }
  // The calls scenario's farm runs its trackers whatever the dispatcher is told (the oracle's true node, the
  // raw fix's): they give gnss_ingest's association its beliefs and the planner of idle robots its views.
  if (spec_.tracker == Tracker::kTpf || config.scenario == Scenario::kCalls) {
    const std::string tpf_file = resolveConfigFile(config.tpf_config, "tpf.yaml");
    const tpf::TpfParams base = tpf_file.empty() ? tpf::TpfParams() : tpf::TpfParams::fromYamlFile(tpf_file);
    const tpf::TpfParams params =
        tpf::TpfParams::presetForMethod(spec_.tracker == Tracker::kTpf ? spec_.tpf_preset : "tpf", base);
    trackers_ = std::make_unique<tpf::TrackerFleet>(map_, [this](tpf::TrackerFleet::Track& t) {
      const tpf::Belief& b = t.filter->belief();
      if (b.initialised) gnss_->addBelief(t.id, b.stamp, b.nodes, b.masses);
    });
    for (std::size_t i = 0; i < n; ++i) {
      std::string error;
      // A run's filters are seeded from the run's seed; with tracker_seed as tpf_tracker with ~seed seeds
      // them.
      const std::uint64_t seed = config.tracker_seed
                                     ? tpf::TrackerFleet::seedFor(scoring_[i].id, config.tracker_seed)
                                     : sim::deriveSeed(config.seed, 1000 + i);
      if (!trackers_->add(scoring_[i].id, params, seed, &error))
        throw std::runtime_error("tracker of " + scoring_[i].id + ": " + error);
    }
  }
  if (config.scenario == Scenario::kCalls) {
    if (spec_.tracker == Tracker::kUkf)
      throw std::runtime_error("the calls scenario has no ukf_metric dispatch");
    // config/dispatcher.yaml as the dispatcher node loads it (its own keys and the dispatcher's).
    const std::string file = resolveConfigFile(config.dispatcher_config, "dispatcher.yaml");
    dispatcher_options_ = file.empty() ? dispatch::DispatcherNodeOptions()
                                       : dispatch::DispatcherNodeOptions::fromYaml(YAML::LoadFile(file));
    dispatch::DispatcherOptions o = dispatcher_options_.dispatcher;
    if (o.storage_node.empty()) o.storage_node = dispatch::defaultStorageNode(*map_);
    std::vector<std::string> robot_ids;
    for (std::size_t r = 0; r < simulator_.numRobots(); ++r) robot_ids.push_back(simulator_.robot(r).id());
    dispatcher_ = std::make_unique<dispatch::CallDispatcher>(map_, o, robot_ids);
    if (config.idle_robots == "nbs") {
      makePlanner(nbs::Policy::kNextBestSense);
      idle_.resize(simulator_.numRobots());
    } else if (config.idle_robots != "stay") {
      throw std::runtime_error("idle_robots '" + config.idle_robots + "': expected nbs or stay");
    }
  } else if (spec_.policy != RobotPolicy::kPatrol) {
    makePlanner(spec_.policy == RobotPolicy::kNbs ? nbs::Policy::kNextBestSense
                                                  : nbs::Policy::kEstimatedNode);
  }
}

void GraphRun::makePlanner(nbs::Policy policy) {
  // config/nbs.yaml as the nbs_planner node loads it (planner keys, planning_period, battery_level,
  // what_if_seed); the method (or the calls scenario) sets the policy.
  const std::string nbs_file = resolveConfigFile(config_.nbs_config, "nbs.yaml");
  nbs::PlannerConfig pc;
  std::uint64_t what_if_seed = 1;
  if (!nbs_file.empty()) {
    const nbs::NbsPlannerNodeOptions node = nbs::NbsPlannerNodeOptions::fromYamlFile(nbs_file);
    pc = node.planner;
    replan_period_ = node.planning_period;
    battery_level_ = node.battery_level;
    what_if_seed = static_cast<std::uint64_t>(std::max(0, node.what_if_seed));
  }
  pc.policy = policy;
  planner_ = std::make_unique<nbs::NextBestSensePlanner>(map_, pc);
  tray_clock_ = std::make_unique<nbs::TrayClock>(pc.call_due_weight, pc.tray_time_mean);
  for (const auto& s : scoring_)
    sources_.push_back(std::make_unique<nbs::TpfBeliefSource>(s.id, *trackers_->find(s.id)->filter,
                                                              what_if_seed ? what_if_seed : 1));
}

void GraphRun::publish(const core::Observation& obs) {
  if (trackers_) result_.observations += trackers_->process(obs).size();
  gnss_->useIdentified(obs);
}

void GraphRun::onFix(const sim::GnssFixWithTruth& f) {
  Scoring& s = scoring_.at(f.picker_index);
  if (f.error.allFinite()) s.true_gnss_error = f.error;
  sensors::GnssFleet::Picker& picker = *gnss_->find(s.id);
  const sensors::GnssResult r = gnss_->processFix(picker, f);
  if (!r.accepted()) return;
  if (picker.ingest.counters().accepted == 1 || r.blackout_ended > 0.0) {
    s.restart = f.stamp;
    s.seen_after_restart = std::nan("");
  }
  if (spec_.tracker == Tracker::kRawFix)
    s.raw_fix_node = map_->nearestNode(r.position);
  else if (spec_.tracker == Tracker::kUkf)
    ukf_.addGnss(f.stamp, s.id, *r.observation->position, r.observation->position_covariance);
  else
    publish(*r.observation);
}

void GraphRun::onRfid(const sim::RfidReadingWithTruth& rr) {
  sensors::RfidRead read;
  static_cast<core::RfidReading&>(read) = rr;
  sim::Pose2D mount;  // the antenna pose the node gets from tf: the simulator's (ground truth)
  for (const auto& m : simulator_.config().sensor_layout.rfid_antennas)
    if (m.frame == rr.mount) mount = m.pose;
  const sim::Pose2D antenna = simulator_.robotPose(rr.robot_index).compose(mount);
  read.antenna_pose = Eigen::Vector3d(antenna.x, antenna.y, antenna.yaw);
  const sensors::RfidResult r = rfid_->process(read);
  if (r.observation) {
    const std::size_t before = gnss_->counters().sightings;
    publish(*r.observation);
    result_.bias_sightings += gnss_->counters().sightings - before;
    // The serving robot read the caller's tag: arrival (the robot's own sensing, never the truth).
    const std::string& robot_id = simulator_.robot(rr.robot_index).id();
    if (dispatcher_ && r.observation->identifying) {
      const dispatch::Call* served = dispatcher_->servedBy(robot_id);
      if (served && dispatcher_->rfidRead(robot_id, r.observation->picker_id, rr.stamp, rr.rssi))
        arrived(served->id, rr.robot_index, rr.stamp, "rfid", rr.rssi);
    }
  }
  for (const auto& neg : r.negative) publish(neg);
}

void GraphRun::onScan(const sim::LaserScanWithTruth& s) {
  // The sensor pose the node gets from tf, here the simulator's (ground truth) laser pose.
  const Eigen::Isometry3d fixed_from_sensor = Eigen::Translation3d(s.sensor_pose.x, s.sensor_pose.y, 0.0) *
                                              Eigen::AngleAxisd(s.sensor_pose.yaw, Eigen::Vector3d::UnitZ());
  const std::vector<vision::PersonCandidate> candidates = legs_->scanCandidates(s, fixed_from_sensor);
  const std::vector<vision::TrackedPerson> tracked = legs_->track(s.frame_id, s.stamp, candidates);
  if (spec_.tracker != Tracker::kUkf)  // as leg_detector publishes it: "nobody at these nodes"
    if (auto neg = legs_->negativeObservation(s.frame_id, s.stamp, s, fixed_from_sensor, candidates, *map_,
                                              s.robot_id))
      publish(*neg);
  result_.lidar_detections += tracked.size();
  std::vector<Eigen::Vector2d> people;
  // Identity for the anonymous people, as gnss_ingest gives it.
  std::vector<core::Observation> scan_people;
  for (const auto& t : tracked)
    scan_people.push_back(vision::LegPipeline::observation(t, *map_, s.stamp, s.robot_id));
  const std::vector<sensors::AssociationResult> scan_results = gnss_->associate(scan_people);  // jointly
  for (std::size_t ti = 0; ti < tracked.size(); ++ti) {
    const auto& t = tracked[ti];
    const sensors::AssociationResult& a = scan_results[ti];
    if (a.picker >= 0 && dispatcher_) {  // the serving robot's own identified person: arrival when near
      const dispatch::Call* served = dispatcher_->servedBy(s.robot_id);
      const double d = (t.position - simulator_.robotPose(s.robot_index).position()).norm();
      if (served && dispatcher_->lidarPerson(s.robot_id, a.observation.picker_id, s.stamp, d,
                                             a.probabilities[a.picker]))
        arrived(served->id, s.robot_index, s.stamp, "lidar", a.probabilities[a.picker]);
    }
    if (a.picker >= 0) {
      ++result_.identified_detections;
      std::size_t nearest = 0;
      double best = 1e300;
      for (std::size_t j = 0; j < scoring_.size(); ++j) {
        const double d = (simulator_.pickerPose(j).position() - t.position).norm();
        if (d < best) best = d, nearest = j;
      }
      if (best < 1.0 && nearest != static_cast<std::size_t>(a.picker)) {
        ++result_.wrong_identifications;
        wrong_identity_stamps_[static_cast<std::size_t>(a.picker)].push_back(s.stamp);
        wrong_identity_stamps_[nearest].push_back(s.stamp);
      }
    }
    if (a.bias.accepted) {
      ++result_.bias_sightings;
      Scoring& seen = scoring_[static_cast<std::size_t>(a.picker)];
      seen.lidar_sighting_stamp = s.stamp;
      seen.lidar_sighting_error =
          (simulator_.pickerPose(static_cast<std::size_t>(a.picker)).position() - t.position).norm();
      if (!std::isnan(seen.restart) && std::isnan(seen.seen_after_restart)) seen.seen_after_restart = s.stamp;
    }
    if (a.concerns_nobody) continue;  // nobody we track (clutter under the association)
    if (spec_.tracker != Tracker::kUkf)
      publish(a.observation);
    else if (a.picker >= 0)
      ukf_.addGnss(s.stamp, a.observation.picker_id, t.position, a.observation.position_covariance);
    else
      people.push_back(t.position);
  }
  if (!people.empty()) ukf_.addDetections(s.stamp, people);
}

void GraphRun::arrived(std::uint64_t call_id, std::size_t robot, double stamp, const char* by,
                       double evidence) {
  OpenCall& c = open_calls_.at(call_id);
  c.arrived = true;
  c.record.arrival_s =
      dispatcher_->find(call_id)->arrived_at - c.record.stamp;  // as the dispatcher declared it
  c.record.arrival_distance =
      (simulator_.robotPose(robot).position() - simulator_.pickerPose(c.picker).position()).norm();
  c.record.false_arrival = c.record.arrival_distance > 3.0;
  c.record.arrived_by = by;
  c.record.arrival_evidence = evidence;
}

void GraphRun::onCall(const sim::PickerCall& call) {
  if (!dispatcher_) return;
  std::string error;
  const auto id = dispatcher_->call(call.picker_id, call.stamp, &error);
  if (!id) throw std::runtime_error("call of " + call.picker_id + " refused: " + error);
  // The reported row, as the dispatcher node sends it: evidence for the picker's filter (a filter that does
  // not accept the sensor, e.g. Khan's GNSS-only one, ignores it).
  dispatch::CallInput input;
  input.picker_id = call.picker_id;
  input.row = call.reported_row;
  const dispatch::CheckedCall checked =
      dispatch::checkCall(input, *map_, nullptr, dispatcher_options_.max_fix_distance);
  if (checked.row_lane != topology::kNoLane && dispatcher_options_.row_evidence_floor < 1.0 && trackers_ &&
      spec_.tracker == Tracker::kTpf)
    publish(dispatch::reportedRowObservation(*map_, checked.row_lane, call.picker_id, call.stamp,
                                             dispatcher_options_.row_evidence_floor));
  OpenCall c;
  c.picker = call.picker_index;
  c.record.picker_id = call.picker_id;
  c.record.stamp = call.stamp;
  c.record.arrival_s = std::numeric_limits<double>::infinity();
  c.record.reported_row = !call.reported_row.empty();
  open_calls_[*id] = c;
}

void GraphRun::dispatchCalls(double now) {
  for (const auto& [id, c] : open_calls_) {
    const std::string& picker_id = c.record.picker_id;
    const NodeIndex est = estimate(c.picker);
    if (spec_.tracker == Tracker::kTpf && spec_.policy != RobotPolicy::kEstimatedNode) {
      const tpf::TopologicalParticleFilter& f = *trackers_->find(picker_id)->filter;
      if (f.initialised()) dispatcher_->setBelief(picker_id, f.belief().nodes, f.belief().masses);
    } else if (est != topology::kInvalidNode) {
      dispatcher_->setBelief(picker_id, {est},
                             {1.0});  // one node: the oracle's, the raw fix's or the MAP node
    }
  }
  for (std::size_t r = 0; r < simulator_.numRobots(); ++r)
    dispatcher_->setRobotNode(simulator_.robot(r).id(), simulator_.robot(r).currentNode());
  for (const dispatch::Goal& g : dispatcher_->update(now)) {
    const std::size_t r = *simulator_.robotIndex(g.robot_id);
    simulator_.setRobotGoal(r, g.node);
    OpenCall& c = open_calls_.at(g.call_id);
    if (g.state == dispatch::CallState::kAssigned) {  // the robot starts serving: scoring starts
      c.robot = r;
      c.robot_at = simulator_.robotPose(r).position();
      c.robot_node = simulator_.robot(r).currentNode();
      // A robot already in a lane (an idle robot the planner sent there) leaving it has not entered it.
      c.inside = map_->lane(c.robot_node);
      c.record.first_target_in_picker_lane =
          map_->lane(g.node) != topology::kNoLane && map_->lane(g.node) == simulator_.pickerLane(c.picker);
      recordCallPicker(c, now);
    }
  }
  for (auto it = open_calls_.begin(); it != open_calls_.end();) {
    OpenCall& c = it->second;
    const dispatch::Call& call = *dispatcher_->find(it->first);
    if (!call.robot_id.empty() && !c.arrived) {  // on its way: metres and lanes entered
      const Eigen::Vector2d at = simulator_.robotPose(c.robot).position();
      c.record.metres += (at - c.robot_at).norm();
      c.robot_at = at;
      // Driving into a lane: along an edge whose two nodes are in that lane (passing a lane's end on the
      // headland is not entering it).
      const NodeIndex node = simulator_.robot(c.robot).currentNode();
      if (node != c.robot_node) {
        const topology::LaneIndex lane =
            map_->lane(node) == map_->lane(c.robot_node) ? map_->lane(node) : topology::kNoLane;
        if (lane != c.inside && lane != topology::kNoLane && lane != simulator_.pickerLane(c.picker)) {
          ++c.record.wrong_lane_entries;
          if (call.target == topology::kInvalidNode || map_->lane(call.target) != lane)
            ++c.record.through_lane_entries;
        }
        c.inside = lane;
        c.robot_node = node;
      }
    }
    if (!c.released && (call.state == dispatch::CallState::kToStorage || !call.open())) {
      simulator_.releasePicker(c.picker);  // the trays were loaded: the picker walks on
      c.released = true;
    }
    if (!call.open()) {
      recordWaits(c.record, call, now);
      result_.calls.push_back(c.record);
      it = open_calls_.erase(it);
    } else {
      ++it;
    }
  }
}

void GraphRun::recordCallPicker(OpenCall& c, double now) {
  CallRecord& r = c.record;
  const std::string& id = r.picker_id;
  const topology::LaneIndex lane = simulator_.pickerLane(c.picker);
  if (trackers_) {
    const tpf::Belief& b = trackers_->find(id)->filter->belief();
    std::map<topology::LaneIndex, double> per_lane = map_->massPerLane(b.nodes, b.masses);
    r.top_lane_mass = 0.0;
    for (const auto& [l, m] : per_lane)
      if (l != topology::kNoLane) r.top_lane_mass = std::max(r.top_lane_mass, m);
    if (lane != topology::kNoLane) r.true_lane_mass = per_lane.count(lane) ? per_lane[lane] : 0.0;
  }
  const sensors::GnssBiasEstimator& bias = gnss_->find(id)->ingest.bias();
  // The sighting may carry the step's own stamp, a rounding above `now`.
  r.sighting_age_s =
      bias.sighted() ? std::max(0.0, now - bias.lastSighting()) : std::numeric_limits<double>::infinity();
  // The last accepted sighting was this LiDAR person (not a tag read since): how far from the picker it was.
  const Scoring& seen = scoring_[c.picker];
  if (bias.sighted() && seen.lidar_sighting_stamp == bias.lastSighting())
    r.last_sighting_error_m = seen.lidar_sighting_error;
  const Eigen::Vector2d& error = seen.true_gnss_error;
  if (error.allFinite()) r.bias_residual_m = (error - bias.applied(now)).norm();
  const std::vector<double>& wrong = wrong_identity_stamps_[c.picker];
  r.wrong_identities_600s = static_cast<std::size_t>(
      std::count_if(wrong.begin(), wrong.end(), [&](double t) { return t <= now && t > now - 600.0; }));
}

void GraphRun::recordWaits(CallRecord& r, const dispatch::Call& call, double now) {
  r.queued_s =
      std::isnan(call.assigned_at) ? std::numeric_limits<double>::infinity() : call.assigned_at - call.stamp;
  if (std::isnan(call.holding_since)) return;
  const double end = !std::isnan(call.hold_ended)   ? call.hold_ended
                     : !std::isnan(call.arrived_at) ? call.arrived_at
                                                    : now;
  r.held_s = end - call.holding_since;
}

void GraphRun::finish(double now) {
  for (auto& [id, c] : open_calls_) {
    recordWaits(c.record, *dispatcher_->find(id), now);
    result_.calls.push_back(c.record);
  }
  open_calls_.clear();
}

void GraphRun::endOfStep(double now) {
  if (trackers_) trackers_->predictDue(now);
  if (dispatcher_) {
    dispatchCalls(now);
    if (planner_) positionIdleRobots(now);
    return;
  }
  if (!planner_ || !(simulator_.robot(0).atGoal() || now - last_plan_ >= replan_period_)) return;
  const nbs::PlanResult plan = planner_->plan(simulator_.robot(0).currentNode(), battery_level_, views());
  if (plan.ok()) simulator_.setRobotGoal(0, plan.ranked.front().node);
  last_plan_ = now;
}

std::vector<nbs::BeliefSource*> GraphRun::views() {
  std::vector<nbs::BeliefSource*> out;
  for (auto& source : sources_) out.push_back(source.get());
  return out;
}

void GraphRun::positionIdleRobots(double now) {
  std::vector<std::size_t> due;
  for (std::size_t r = 0; r < simulator_.numRobots(); ++r) {
    IdleRobot& idle = idle_[r];
    const bool serving = dispatcher_->servedBy(simulator_.robot(r).id()) != nullptr;
    const bool released = idle.serving && !serving;  // nbs_planner plans at once when the call goal is freed
    idle.serving = serving;
    if (serving) idle.goal = {};
    if (!serving && (released || now - idle.last_plan >= replan_period_)) due.push_back(r);
  }
  if (due.empty()) return;
  // Every robot's goal as the planners see it on the goal topics: a served call's target (claiming its
  // picker), else the planner's last goal.
  std::vector<nbs::Claim> goals;
  for (std::size_t r = 0; r < simulator_.numRobots(); ++r) {
    const std::string& id = simulator_.robot(r).id();
    if (const dispatch::Call* c = dispatcher_->servedBy(id)) {
      if (c->target != topology::kInvalidNode) goals.push_back({id, c->target, c->picker_id});
    } else if (idle_[r].goal.node != topology::kInvalidNode) {
      goals.push_back(idle_[r].goal);
    }
  }
  const std::vector<nbs::BeliefSource*> pickers = views();
  // The pickers' call-due weights from the dispatcher's calls, as nbs_planner reads them from its ~status.
  if (tray_clock_->callDueWeight() > 0.0)
    for (const dispatch::Call& c : dispatcher_->calls())
      tray_clock_->observeCall(c.picker_id, c.stamp, c.arrived_at, c.open());
  const nbs::PickerWeights weights = tray_clock_->weights(pickers, now);
  for (std::size_t r : due) {
    const std::string& id = simulator_.robot(r).id();
    const nbs::PlanResult plan = planner_->plan(simulator_.robot(r).currentNode(), battery_level_, pickers,
                                                nbs::claimsFor(id, goals), weights);
    idle_[r].last_plan = now;
    if (!plan.ok()) continue;
    const nbs::Claim goal{id, plan.ranked.front().node, plan.ranked.front().target_picker};
    if (goal.node != idle_[r].goal.node) {
      simulator_.setRobotGoal(r, goal.node);
      ++result_.idle_goals;
    }
    idle_[r].goal = goal;
    goals.erase(
        std::remove_if(goals.begin(), goals.end(), [&](const nbs::Claim& g) { return g.robot_id == id; }),
        goals.end());
    goals.push_back(goal);
  }
}

NodeIndex GraphRun::estimate(std::size_t i) const {
  switch (spec_.tracker) {
    case Tracker::kTpf: {
      const tpf::TopologicalParticleFilter& f = *trackers_->tracks().at(scoring_[i].id)->filter;
      return f.initialised() ? f.belief().map_node : topology::kInvalidNode;
    }
    case Tracker::kUkf: {
      const auto p = ukf_.estimate(scoring_[i].id);
      return p ? map_->nearestNode(*p) : topology::kInvalidNode;
    }
    case Tracker::kRawFix:
      return scoring_[i].raw_fix_node;
    case Tracker::kOracle:
      return simulator_.pickerNearestNode(i);
  }
  return topology::kInvalidNode;
}

void GraphRun::sample(double t) {
  for (std::size_t i = 0; i < scoring_.size(); ++i) {
    const NodeIndex est = estimate(i);
    if (est == topology::kInvalidNode) continue;  // no estimate yet (before the first observation)
    Scoring& s = scoring_[i];
    result_.samples.push_back(computeError(*map_, est, simulator_.pickerPose(i).position(), t, s.id));
    const ErrorSample& e = result_.samples.back();
    if (s.true_gnss_error.allFinite()) {
      const sensors::GnssBiasEstimator& b = gnss_->find(s.id)->ingest.bias();
      BiasSample bs;
      bs.sighting_age = b.sighted() ? t - b.lastSighting() : std::numeric_limits<double>::infinity();
      bs.residual = (s.true_gnss_error - b.applied(t)).norm();
      bs.lane_applicable = e.lane_applicable;
      bs.in_true_lane = e.in_true_lane;
      result_.bias_samples.push_back(bs);
    }
    if (!std::isnan(s.seen_after_restart)) {
      const double since = t - s.seen_after_restart;
      const bool right = e.lane_applicable && e.in_true_lane;
      if (right || since > 120.0) {
        result_.lane_delays.push_back(right ? since : std::numeric_limits<double>::infinity());
        s.restart = s.seen_after_restart = std::nan("");
      }
    }
  }
}

}  // namespace

RunResult runOnce(std::shared_ptr<const topology::TopologicalMap> map, const RunConfig& config) {
  const std::string why = methodUnavailableReason(config.method, config);
  if (!why.empty()) throw std::runtime_error("method " + config.method + " unavailable: " + why);
  const auto wall0 = std::chrono::steady_clock::now();
  GraphRun run(std::move(map), config);
  sim::FarmSimulator& simulator = run.simulator();
  // One raw measurement of the simulator; the streams are merged into stamp order (ties: gnss, rfid, laser).
  struct Event {
    double stamp;
    int kind;
    std::size_t index;
  };
  double next_sample = config.sample_period;
  while (simulator.time() < config.duration - 1e-9) {
    const sim::SimOutputs out =
        simulator.advanceTo(std::min(config.duration, simulator.time() + config.step));
    std::vector<Event> events;
    for (std::size_t k = 0; k < out.gnss.size(); ++k) events.push_back({out.gnss[k].stamp, 0, k});
    for (std::size_t k = 0; k < out.rfid.size(); ++k) events.push_back({out.rfid[k].stamp, 1, k});
    for (std::size_t k = 0; k < out.scans.size(); ++k) events.push_back({out.scans[k].stamp, 2, k});
    std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) {
      return a.stamp != b.stamp ? a.stamp < b.stamp : a.kind < b.kind;
    });
    for (const sim::PickerCall& call : out.calls) run.onCall(call);
    for (const Event& e : events) {
      if (e.kind == 0) run.onFix(out.gnss[e.index]);
      if (e.kind == 1) run.onRfid(out.rfid[e.index]);
      if (e.kind == 2) run.onScan(out.scans[e.index]);
    }
    run.endOfStep(simulator.time());
    for (; next_sample <= simulator.time() + 1e-9; next_sample += config.sample_period)
      run.sample(next_sample);
  }
  run.finish(simulator.time());
  RunResult result = std::move(run.result());
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

namespace {

// The bias estimate's residual and the right-lane share by age of the last sighting, over all runs.
void writeBiasByAge(const std::string& path, const std::vector<RunResult>& runs, std::ostream& log) {
  const std::vector<double> edges = {0.0, 10.0, 30.0, 60.0, 120.0, std::numeric_limits<double>::infinity()};
  const std::vector<std::string> names = {"0-10", "10-30", "30-60", "60-120", ">120", "never"};
  std::vector<double> residual(names.size(), 0.0);
  std::vector<std::size_t> count(names.size(), 0), lane(names.size(), 0), right(names.size(), 0);
  for (const RunResult& r : runs)
    for (const BiasSample& b : r.bias_samples) {
      std::size_t k = names.size() - 1;
      for (std::size_t e = 0; e + 1 < edges.size(); ++e)
        if (b.sighting_age >= edges[e] && b.sighting_age < edges[e + 1]) k = e;
      residual[k] += b.residual;
      ++count[k];
      if (b.lane_applicable) {
        ++lane[k];
        if (b.in_true_lane) ++right[k];
      }
    }
  std::ofstream out(path);
  out << "sighting_age_s,samples,bias_residual_mean_m,right_lane_share\n";
  log << "    by age of the last bias sighting (s: share of samples, residual m, right lane):";
  std::size_t total = 0;
  for (auto c : count) total += c;
  for (std::size_t k = 0; k < names.size(); ++k) {
    const double res = count[k] ? residual[k] / count[k] : std::nan("");
    const double share = lane[k] ? static_cast<double>(right[k]) / lane[k] : std::nan("");
    out << names[k] << "," << count[k] << "," << res << "," << share << "\n";
    if (count[k])
      log << "  " << names[k] << ": " << std::setprecision(2) << std::fixed
          << static_cast<double>(count[k]) / std::max<std::size_t>(1, total) << ", " << res << ", " << share
          << std::defaultfloat;
  }
  log << "\n";
}

// The calls scenario's table, one row per method: what the farm feels of a call.
struct CallSummary {
  std::string method;
  std::size_t calls = 0, arrived = 0, false_arrivals = 0, reported_row = 0;
  double arrival_s_mean = 0.0, wrong_lane_entries_per_call = 0.0, metres_mean = 0.0, right_lane_share = 0.0;
};

CallSummary summariseCalls(const std::string& method, const std::vector<RunResult>& runs, double right_lane) {
  CallSummary s;
  s.method = method;
  s.right_lane_share = right_lane;
  double arrival = 0.0, wrong = 0.0, metres = 0.0;
  for (const RunResult& r : runs)
    for (const CallRecord& c : r.calls) {
      ++s.calls;
      wrong += static_cast<double>(c.wrong_lane_entries);
      metres += c.metres;
      s.false_arrivals += c.false_arrival ? 1 : 0;
      s.reported_row += c.reported_row ? 1 : 0;
      if (std::isfinite(c.arrival_s)) {
        ++s.arrived;
        arrival += c.arrival_s;
      }
    }
  s.arrival_s_mean = s.arrived ? arrival / static_cast<double>(s.arrived) : std::nan("");
  s.wrong_lane_entries_per_call = s.calls ? wrong / static_cast<double>(s.calls) : std::nan("");
  s.metres_mean = s.calls ? metres / static_cast<double>(s.calls) : std::nan("");
  return s;
}

// summary.csv and summary.md of the calls scenario (arrival_ratio_oracle: against the oracle row, when run).
void writeCallSummaries(const std::string& dir, const std::string& title,
                        const std::vector<CallSummary>& rows) {
  double oracle = std::nan("");
  for (const CallSummary& s : rows)
    if (s.method == "oracle") oracle = s.arrival_s_mean;
  std::ofstream csv(dir + "/summary.csv"), md(dir + "/summary.md");
  csv << "method,calls,arrived,arrival_s_mean,arrival_ratio_oracle,wrong_lane_entries_per_call,false_"
         "arrivals,"
         "metres_per_call,right_lane_share,calls_with_reported_row\n";
  md << "### " << title
     << "\n\n| method | calls | arrived | call-to-arrival [s] | vs oracle | wrong-lane entries per call "
        "| false arrivals | metres per call | right-lane share |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const CallSummary& s : rows) {
    const double ratio = s.arrival_s_mean / oracle;
    csv << s.method << "," << s.calls << "," << s.arrived << "," << s.arrival_s_mean << "," << ratio << ","
        << s.wrong_lane_entries_per_call << "," << s.false_arrivals << "," << s.metres_mean << ","
        << s.right_lane_share << "," << s.reported_row << "\n";
    md << std::fixed << "| " << s.method << " | " << s.calls << " | " << s.arrived << " | "
       << std::setprecision(1) << s.arrival_s_mean << " | " << std::setprecision(2) << ratio << "x | "
       << std::setprecision(3) << s.wrong_lane_entries_per_call << " | " << s.false_arrivals << " | "
       << std::setprecision(1) << s.metres_mean << " | " << std::setprecision(3) << s.right_lane_share
       << " |\n"
       << std::defaultfloat;
  }
}

// Keys of the configuration files the runs read that their schemas do not know (typos), logged once here as
// the nodes warn at start-up; a bad value is left to the runs, which report it per run.
void logUnknownKeys(const RunConfig& config, std::ostream& log) {
  auto check = [&log](const std::string& file, auto&& load) {
    if (file.empty()) return;
    std::vector<std::string> unknown;
    try {
      load(file, &unknown);
    } catch (const std::exception&) {
      return;
    }
    for (const std::string& u : unknown) log << "  warning: " << file << ": " << u << "\n";
  };
  check(resolveConfigFile(config.gnss_config, "gnss_ingest.yaml"),
        sensors::GnssIngestNodeOptions::fromYamlFile);
  check(resolveConfigFile(config.rfid_config, "rfid_ranging.yaml"),
        sensors::RfidRangingNodeOptions::fromYamlFile);
  check(resolveConfigFile(config.tpf_config, "tpf.yaml"), tpf::TpfParams::fromYamlFile);
  check(resolveConfigFile(config.nbs_config, "nbs.yaml"), nbs::NbsPlannerNodeOptions::fromYamlFile);
}

}  // namespace

namespace {

// The runs of one method, seeds config.seed + k, over config.jobs threads; the first error is thrown.
std::vector<RunResult> runSeeds(const std::shared_ptr<const topology::TopologicalMap>& map,
                                const RunConfig& rc, const ExperimentConfig& config) {
  std::vector<RunResult> runs(config.runs);
  std::vector<std::string> errors(config.runs);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t k = next++; k < config.runs; k = next++) {
      RunConfig r = rc;
      r.seed = config.seed + k;
      try {
        runs[k] = runOnce(map, r);
      } catch (const std::exception& e) {
        errors[k] = e.what();
      }
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t j = 1; j < std::max<std::size_t>(1, std::min(config.jobs, config.runs)); ++j)
    pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
  for (std::size_t k = 0; k < config.runs; ++k)
    if (!errors[k].empty())
      throw std::runtime_error("method " + rc.method + " run " + std::to_string(k) + ": " + errors[k]);
  return runs;
}

// One calls_<k>.csv per run: every call, scored from the simulator's truth.
void writeCallFiles(const fs::path& dir, const std::vector<RunResult>& runs) {
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::ofstream calls(dir / ("calls_" + std::to_string(k) + ".csv"));
    calls << "picker_id,stamp,arrival_s,wrong_lane_entries,through_lane_entries,first_target_in_picker_lane,"
             "false_arrival,arrival_distance,arrived_by,arrival_evidence,metres,reported_row,"
             "true_lane_mass,top_lane_mass,sighting_age_s,last_sighting_error_m,bias_residual_m,"
             "wrong_identities_600s,queued_s,held_s\n";
    for (const CallRecord& c : runs[k].calls)
      calls << c.picker_id << "," << c.stamp << "," << c.arrival_s << "," << c.wrong_lane_entries << ","
            << c.through_lane_entries << "," << c.first_target_in_picker_lane << "," << c.false_arrival << ","
            << c.arrival_distance << "," << c.arrived_by << "," << c.arrival_evidence << "," << c.metres
            << "," << c.reported_row << "," << c.true_lane_mass << "," << c.top_lane_mass << ","
            << c.sighting_age_s << "," << c.last_sighting_error_m << "," << c.bias_residual_m << ","
            << c.wrong_identities_600s << "," << c.queued_s << "," << c.held_s << "\n";
  }
}

// The LiDAR people and bias sightings of a method's runs, and bias_by_age.csv in its folder.
void logLidarPeople(const std::vector<RunResult>& runs, const std::string& dir, std::ostream& log) {
  std::size_t people = 0, identified = 0, wrong = 0, sightings = 0;
  for (const RunResult& r : runs) {
    people += r.lidar_detections;
    identified += r.identified_detections;
    wrong += r.wrong_identifications;
    sightings += r.bias_sightings;
  }
  log << "    LiDAR people: " << people << ", identified " << identified << " (wrong picker " << wrong
      << "), bias sightings accepted " << sightings << "\n";
  std::vector<double> delays;
  for (const RunResult& r : runs) delays.insert(delays.end(), r.lane_delays.begin(), r.lane_delays.end());
  if (!delays.empty()) {
    std::sort(delays.begin(), delays.end());
    const auto within = std::count_if(delays.begin(), delays.end(), [](double d) { return d <= 30.0; });
    log << "    first sighting after a first fix or a blackout: " << delays.size()
        << ", lane right within 30 s in " << std::setprecision(2) << std::fixed
        << static_cast<double>(within) / delays.size() << ", median " << std::setprecision(1)
        << delays[delays.size() / 2] << " s" << std::defaultfloat << "\n";
  }
  writeBiasByAge((fs::path(dir) / "bias_by_age.csv").string(), runs, log);
}

}  // namespace

ExperimentResult runExperiment(const ExperimentConfig& config, std::ostream& log) {
  const auto wall0 = std::chrono::steady_clock::now();
  auto map = std::make_shared<const topology::TopologicalMap>(topology::loadMap(config.map_path));
  const std::vector<std::string> methods =
      config.methods.empty() ? defaultMethods(config.scenario) : config.methods;
  for (const auto& m : methods)
    if (!isKnownMethod(m)) throw std::invalid_argument("unknown method '" + m + "'");
  if (config.runs == 0) throw std::invalid_argument("--runs must be at least 1");
  if (!(config.duration > 0.0)) throw std::invalid_argument("--duration must be > 0");
  fs::create_directories(config.out_dir);

  ExperimentResult res;
  log << "experiment: map " << map->name() << " (" << map->numNodes() << " nodes, " << map->numLanes()
      << " lanes), scenario " << toString(config.scenario) << ", " << config.runs << " runs, seed "
      << config.seed << ", " << config.duration << " s simulated, " << config.jobs << " job(s)\n";
  logUnknownKeys(config.run, log);
  std::vector<CallSummary> call_rows;
  for (const auto& method : methods) {
    RunConfig rc = config.run;
    rc.scenario = config.scenario;
    rc.method = method;
    rc.duration = config.duration;
    const std::string why = methodUnavailableReason(method, rc);
    if (!why.empty()) {
      log << "  " << method << ": UNAVAILABLE (" << why << ")\n";
      res.rows.push_back(unavailableMethod(method, why));
      continue;
    }
    const auto m0 = std::chrono::steady_clock::now();
    std::vector<RunResult> runs = runSeeds(map, rc, config);

    fs::create_directories(fs::path(config.out_dir) / method);
    std::vector<std::vector<ErrorSample>> samples;
    if (config.scenario == Scenario::kCalls) writeCallFiles(fs::path(config.out_dir) / method, runs);
    for (std::size_t k = 0; k < config.runs; ++k) {
      writeRunCsv((fs::path(config.out_dir) / method / ("run_" + std::to_string(k) + ".csv")).string(), *map,
                  runs[k].samples);
      samples.push_back(std::move(runs[k].samples));
    }
    MethodSummary row = summariseMethod(method, samples);
    res.rows.push_back(row);
    if (config.scenario == Scenario::kCalls) {
      call_rows.push_back(summariseCalls(method, runs, row.right_lane_share));
      const CallSummary& c = call_rows.back();
      log << "    calls " << c.calls << ", arrived " << c.arrived << ", call-to-arrival " << std::fixed
          << std::setprecision(1) << c.arrival_s_mean << " s, wrong-lane entries per call "
          << std::setprecision(3) << c.wrong_lane_entries_per_call << ", false arrivals " << c.false_arrivals
          << ", metres per call " << std::setprecision(1) << c.metres_mean << std::defaultfloat << "\n";
    }
    res.series.push_back(binErrors(method, samples, 0.0, std::max(5.0, config.duration / 100.0)));
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - m0).count();
    log << "  " << method << ": euclidean " << std::fixed << std::setprecision(2) << row.euclidean_mean
        << " (" << row.euclidean_std << ") m, topological " << row.topological_mean << " ("
        << row.topological_std << ") nodes, right lane " << std::setprecision(3) << row.right_lane_share
        << " (" << row.right_lane_share_std << ")" << std::setprecision(1) << "  [" << secs << " s wall]\n"
        << std::defaultfloat;
    if (specOf(method).lidar) logLidarPeople(runs, (fs::path(config.out_dir) / method).string(), log);
  }
  std::ostringstream title;
  title << (config.scenario == Scenario::kCalls ? "Calls" : "Table II") << ", scenario "
        << toString(config.scenario) << ": map " << map->name() << ", " << config.runs << " runs, seeds "
        << config.seed << ".." << config.seed + config.runs - 1 << ", " << config.duration << " s simulated";
  if (config.scenario == Scenario::kCalls) {
    title << ", " << config.run.pickers << " pickers, " << config.run.robots << " robots";
    writeCallSummaries(config.out_dir, title.str(), call_rows);
    writeSummaryCsv((fs::path(config.out_dir) / "errors_summary.csv").string(), res.rows);
  } else {
    writeSummaryCsv((fs::path(config.out_dir) / "summary.csv").string(), res.rows);
    writeSummaryMarkdown((fs::path(config.out_dir) / "summary.md").string(), title.str(), res.rows);
  }
  if (!res.series.empty()) plotErrors((fs::path(config.out_dir) / "errors.png").string(), res.series);
  res.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  log << "experiment: wrote " << config.out_dir << "/summary.csv, summary.md"
      << (res.series.empty() ? "" : ", errors.png") << " in " << std::setprecision(1) << std::fixed
      << res.wall_seconds << " s wall\n"
      << std::defaultfloat;
  return res;
}

}  // namespace eval
}  // namespace picker_localisation
