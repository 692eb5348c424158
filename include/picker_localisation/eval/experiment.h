// The offline Table II experiment runner (Navigate-and-Seek Sec. VI): in-process, deterministic, no roscore.
// Per run: farm simulator raw measurements -> the real front-end core classes (GnssIngest for fixes,
// LegDetector on the simulated scans, RfidObservationModel on reads) -> Observations -> one tracker per
// picker (TopologicalParticleFilter with the method's parameter preset, or the ukf_metric baseline) ->
// metrics.
//
// Scenarios fix the pickers and the default method list:
//   single      1 picker, 1 robot  (Table II "Single picker")
//   navigation  1 picker, 1 robot  (Table II "Navigation Strategy")
//   multi       3 pickers, 1 robot (Table II "Multiple pickers")
//   calls       `pickers` pickers fill trays and call, `robots` robots answer (dispatch::CallDispatcher),
//               robots serving no call positioned by the Next-Best-Sense planner (RunConfig::idle_robots);
//               scored per call: call-to-arrival time, wrong-lane entries, false arrivals, metres driven
// The robot patrols the lanes (simulator patrol `lanes`) unless the method is a navigation policy
// (estimated_node, nbs), whose planner then sets the robot's goals.
// A method whose components are not in this build (or whose data file is missing) is reported unavailable
// with the reason; it is never run with a substitute.
#pragma once

#include <cmath>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/eval/metrics.h"
#include "picker_localisation/eval/report.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace eval {

enum class Scenario { kSingle, kNavigation, kMulti, kCalls };
Scenario parseScenario(const std::string& name);  // throws std::invalid_argument
const char* toString(Scenario s);

// Every method of Table II, in table order.
const std::vector<std::string>& allMethodNames();
// The Table II rows of a scenario.
std::vector<std::string> defaultMethods(Scenario s);
bool isKnownMethod(const std::string& method);

struct RunConfig {
  Scenario scenario = Scenario::kSingle;
  std::string method = "rfid_lidar_gnss";
  std::uint64_t seed = 1;         // simulator seed of this run; trackers derive theirs from it
  double duration = 600.0;        // simulated s (one tour of the Riseholme lanes at 0.5 m/s)
  double sample_period = 1.0;     // s between metric samples (per picker)
  double step = 0.1;              // s, simulator advance between event merges
  double replan_period = 10.0;    // s, navigation policies re-plan at least this often
  // Configuration files shared with the ROS graph (farm_sim, gnss_ingest, tpf_tracker, ...), so the runner
  // and demo.launch simulate the same farm. "" = the package's config/<file> when it exists, else built-in
  // defaults; "none" = built-in defaults.
  std::string leg_model;           // leg classifier model (OpenCV YAML), config/leg_classifier.yml
  std::string tpf_config;          // TPF parameters, config/tpf.yaml (the method preset is applied on top)
  std::string sim_config;          // simulator, config/sim.yaml (seed, pickers, robots, switches set here)
  std::string datum_file;          // geodetic datum of simulator and GnssIngest, config/datum.yaml
  std::string pickers_file;        // pickers (the first 1 or 3 entries), config/pickers.yaml
  std::string gnss_config;         // GnssIngest options, config/gnss_ingest.yaml
  std::string rfid_config;         // RfidObservationModel options, config/rfid_ranging.yaml
  std::string nbs_config;          // planner of estimated_node / nbs, config/nbs.yaml
  std::string vision_config;       // leg_detector section (vision::LegPipelineOptions, as the node): "" =
                                  // config/vision.yaml, then the simulated-laser overlay config/vision_sim.yaml
                                  // (leg_threshold 0.42 = 0.3 at 0.5 deg); else comma-separated files applied in order
  std::size_t pickers = 30;        // calls scenario: pickers (ids picker_<i>; config/pickers.yaml's first)
  std::size_t robots = 10;         // calls scenario: robots (about 1 robot : 3 pickers)
  std::string dispatcher_config;   // calls scenario: dispatch::DispatcherOptions, config/dispatcher.yaml
  // calls scenario: what a robot serving no call does. "nbs": the Next-Best-Sense planner (config/nbs.yaml,
  // policy nbs) positions it over the trackers' beliefs, as nbs_planner does in the ROS graph, with the
  // goals of the other robots (a served call's target included) as claims; "stay": it waits where it is.
  std::string idle_robots = "nbs";
  std::uint64_t tracker_seed = 0;  // 0: trackers seeded from `seed`; else each from its picker id mixed with
                                   // this, as tpf_tracker with ~seed (tpf::TrackerFleet::seedFor)
};

// The file a RunConfig field resolves to ("" = built-in defaults): see RunConfig.
std::string resolveConfigFile(const std::string& value, const std::string& package_file);
// The files whose `leg_detector:` sections the runner's LegPipeline loads, in order, for a RunConfig
// vision_config value ("" = config/vision.yaml then config/vision_sim.yaml; "none" = none; else a comma list).
std::vector<std::string> visionConfigFiles(const std::string& value);

// "" when `method` can run in this build, else one line saying what is missing.
std::string methodUnavailableReason(const std::string& method, const RunConfig& config = RunConfig());

// One metric sample seen from the picker's GNSS bias estimate: how old its last sighting was and how far the
// estimate is from the unit's true error (the simulator's, used for scoring only).
struct BiasSample {
  double sighting_age = 0.0;  // s since the last accepted sighting; +inf before the first
  double residual = 0.0;      // m, |true error - bias estimate| (|true error| while the estimate is unused)
  bool lane_applicable = false, in_true_lane = false;  // as the ErrorSample of the same instant
};

// One call of the calls scenario, scored from the simulator's truth.
struct CallRecord {
  std::string picker_id;
  double stamp = 0.0;                  // s, when the picker called
  double arrival_s = 0.0;              // s from the call to the arrival (+inf: not arrived by the run's end)
  std::size_t wrong_lane_entries = 0;  // lanes the serving robot drove into that the picker was not in
  // Of those, lanes that were not the target's lane then: the route to the target passed through them.
  std::size_t through_lane_entries = 0;
  bool first_target_in_picker_lane = false;  // the first goal the dispatcher gave was in the picker's lane
  bool false_arrival = false;          // arrival declared with the picker more than 3 m from the robot
  double arrival_distance = 0.0;       // m, robot to picker when the arrival was declared (truth)
  std::string arrived_by;              // "rfid" or "lidar": the sensing that declared the arrival
  // The evidence that declared it: for "lidar" the association probability the person was named at, for
  // "rfid" the read's RSSI in dBm.
  double arrival_evidence = std::nan("");
  double metres = 0.0;                 // driven by the serving robot from assignment to arrival
  double queued_s = 0.0;               // s from the call until a robot was assigned (+inf: never)
  double held_s = 0.0;  // s the serving robot waited at a lane end for the belief to commit to a lane
  bool reported_row = false;           // the call carried a reported row
  // What the picker's belief and bias estimate were when a robot was assigned (the farm's tracker, whatever
  // the method tells the dispatcher): where wrong-lane entries come from.
  double true_lane_mass = std::nan("");   // the belief's mass in the picker's true lane (NaN: not in a lane)
  double top_lane_mass = std::nan("");    // the largest mass of any one lane
  double sighting_age_s = std::nan("");   // s since the picker's last accepted bias sighting (+inf: never)
  // m from the picker to the LiDAR person of that sighting, when it was one (NaN: a tag read, or none): a
  // sighting of someone else teaches the bias of a wrong place.
  double last_sighting_error_m = std::nan("");
  double bias_residual_m = std::nan("");  // m, |the unit's true error - the bias estimate applied|
  std::size_t wrong_identities_600s = 0;  // LiDAR people given to or taken from this picker wrongly in the
                                          // 600 s before the call (scoring only)
};

struct RunResult {
  std::vector<CallRecord> calls;  // calls scenario
  std::size_t idle_goals = 0;     // calls scenario: goals the planner gave robots serving no call
  std::vector<ErrorSample> samples;
  std::vector<BiasSample> bias_samples;
  std::size_t observations = 0;  // observations given to trackers
  std::size_t lidar_detections = 0;
  std::size_t identified_detections = 0;  // LiDAR people that the association gave to one picker
  std::size_t bias_sightings = 0;         // of those, accepted by the picker's GNSS bias estimate
  // Scoring: s from the first bias sighting after a picker's first fix or a GNSS blackout until its estimate
  // is first in the right lane (+inf: not within 120 s).
  std::vector<double> lane_delays;
  std::size_t wrong_identifications = 0;  // scoring only: identified as a picker other than the one nearest
                                          // the detection (within 1 m) in the simulator's truth
  double wall_seconds = 0.0;
};

// One run of one method. Throws std::runtime_error when the method is unavailable.
RunResult runOnce(std::shared_ptr<const topology::TopologicalMap> map, const RunConfig& config);

struct ExperimentConfig {
  std::string map_path;
  Scenario scenario = Scenario::kSingle;
  std::vector<std::string> methods;  // empty: defaultMethods(scenario)
  std::size_t runs = 10;
  std::uint64_t seed = 1;  // run k (0-based) uses seed + k, the same for every method
  double duration = 600.0;
  std::string out_dir;
  std::size_t jobs = 1;  // runs executed in parallel (results do not depend on it)
  RunConfig run;         // template for the per-run options (scenario/method/seed/duration set here)
};

struct ExperimentResult {
  std::vector<MethodSummary> rows;
  std::vector<ErrorSeries> series;
  double wall_seconds = 0.0;
};

// Runs every method `runs` times and writes DIR/<method>/run_<k>.csv, DIR/summary.csv, DIR/summary.md and
// DIR/errors.png. Progress and unavailable methods are reported on `log`. Throws std::runtime_error on a bad
// map or an unwritable directory.
ExperimentResult runExperiment(const ExperimentConfig& config, std::ostream& log);

}  // namespace eval
}  // namespace picker_localisation
