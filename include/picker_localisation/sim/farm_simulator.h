// The farm simulator: pickers walking the lanes, their GNSS units, robots driving the graph and the robots'
// sensors, on any topological map, stepped with explicit simulated time (no wall clock; runs as fast as the
// CPU allows). ROS-free; the farm_sim node and the offline experiment runner both drive it.
//
// Determinism: one seed. Every random process owns a std::mt19937_64 seeded from (seed, stream) through
// SplitMix64, where the stream names the process (picker i motion, picker i GNSS, robot r patrol, robot r
// laser, ...). The same seed gives the same numbers, and switching a sensor off or changing the robots' goals
// does not change the pickers' walks or their GNSS errors (so methods compared on one seed see the same
// pickers).
//
// Time: the simulator integrates with a fixed internal step `time_step`; step(dt) / advanceTo(t) run as many
// internal steps as needed (the last one shortened to land exactly on t). Sensors fire on their own grids:
// a sensor of rate f fires at t = k / f (k = 1, 2, ...) as soon as the simulated time reaches it, with the
// scene as of the end of that internal step (stamp = k / f, error <= time_step).
#pragma once

#include "picker_localisation/sim/gnss_model.h"
#include "picker_localisation/sim/lane_layout.h"
#include "picker_localisation/sim/picker_motion.h"
#include "picker_localisation/sim/robot_motion.h"
#include "picker_localisation/sim/sensor_layout.h"
#include "picker_localisation/sim/sensor_models.h"
#include "picker_localisation/sim/sim_types.h"
#include "picker_localisation/topology/topological_map.h"

#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace core {
class PickerRegistry;
}
namespace sim {

struct PickerSpec {
  std::string id;
  bool has_gnss = true;
  std::string rfid_tag;  // "" none
  std::string uwb_tag;   // "" none
  int start_lane = -1;   // position in LaneLayout::lanes() to start in; -1: spread evenly (see FarmSimulator)
};

struct SensorSwitches {
  bool gnss = true;
  bool laser = true;
  bool rfid = true;
  bool uwb = true;
  bool camera = true;
};

// The call scenario: each picker fills trays (tray_time_mean s each on average, drawn uniformly in
// [0.5, 1.5] x the mean from the picker's own generator) and, when they are full, calls a robot and stands
// where it is until releasePicker (the trays were loaded). Off by default: pickers walk without stopping.
struct CallParams {
  bool enabled = false;
  double tray_time_mean = 360.0;       // s (about 6 min on real farms)
  double reported_row_share = 0.0;     // share of calls that carry the row the picker reports
  double wrong_row_probability = 0.1;  // a reported row is a neighbouring lane's with this probability
};

struct SimConfig {
  std::uint64_t seed = 1;
  double time_step = 0.05;          // s, internal integration step
  std::vector<PickerSpec> pickers;  // empty: three default pickers picker_1..3 (tags rfid_000<i>, uwb_000<i>)
  std::size_t num_robots = 1;
  std::vector<std::string> robot_ids;          // empty: robot_1 .. robot_k
  std::vector<std::string> robot_start_nodes;  // node names; empty / missing: spread over lane ends
  PickerMotionParams picker_motion;
  GnssNoiseParams gnss;
  core::DatumConfig datum = riseholmeDatum();
  RobotMotionParams robot_motion;
  RobotSensorLayout sensor_layout;
  LaserParams laser;
  RfidParams rfid;
  UwbParams uwb;
  CameraParams camera;
  ClutterParams clutter;
  SensorSwitches enable;
  CallParams calls;
};

// Overrides the fields present in a YAML mapping shaped like config/sim.yaml (sections seed, time_step,
// robots, picker_motion, gnss, datum, robot_motion, laser, rfid, uwb, camera, clutter, enable). Unknown keys
// are an error. Throws std::runtime_error with one line naming `source` and the key.
void applySimConfigYaml(const YAML::Node& root, SimConfig& config, const std::string& source = "<yaml>");
SimConfig loadSimConfig(const std::string& path);
// PickerSpecs from config/pickers.yaml entries (first RFID tag, UWB tag, has_gnss = gnss_topic non-empty).
std::vector<PickerSpec> pickerSpecsFromRegistry(const core::PickerRegistry& registry);

class FarmSimulator {
 public:
  // Throws std::invalid_argument on an unusable configuration (no robots is fine; a map whose component
  // cannot host a tour, an unknown start node, non-positive rates or time step).
  // Picker i (of n) starts in lane position round(i * L / n) rounded down to an even position (so it walks
  // that lane from its entry end), or at its start_lane when set; on maps without lanes at a node drawn by
  // its own generator, wandering between random nodes.
  FarmSimulator(const topology::TopologicalMap& map, SimConfig config);
  ~FarmSimulator();

  // Advances by dt (>= 0) seconds; returns everything the sensors produced meanwhile.
  SimOutputs step(double dt);
  // Advances to absolute simulated time t (>= time()).
  SimOutputs advanceTo(double t);
  double time() const { return time_; }

  const topology::TopologicalMap& map() const { return *map_; }
  const SimConfig& config() const { return config_; }
  const LaneLayout& laneLayout() const { return layout_; }
  const core::GeodeticDatum& datum() const { return datum_; }

  std::size_t numPickers() const { return pickers_.size(); }
  const PickerSpec& pickerSpec(std::size_t i) const { return config_.pickers.at(i); }
  const SimulatedPicker& picker(std::size_t i) const { return pickers_.at(i); }
  // Ground truth pose of picker i (map frame).
  const Pose2D& pickerPose(std::size_t i) const { return pickers_.at(i).pose(); }
  // Node nearest the true position, and its lane (kNoLane in the headland).
  topology::NodeIndex pickerNearestNode(std::size_t i) const;
  topology::LaneIndex pickerLane(std::size_t i) const;
  std::optional<std::size_t> pickerIndex(const std::string& id) const;

  std::size_t numRobots() const { return robots_.size(); }
  const SimulatedRobot& robot(std::size_t r) const { return robots_.at(r); }
  const Pose2D& robotPose(std::size_t r) const { return robots_.at(r).pose(); }
  std::optional<std::size_t> robotIndex(const std::string& id) const;
  // The call scenario: whether picker i waits for a robot (it called), and the end of that wait (the trays
  // were loaded): it walks on and fills its next trays. Throws std::out_of_range on a bad index.
  bool pickerWaiting(std::size_t i) const { return waiting_.at(i); }
  void releasePicker(std::size_t i);
  // Retargets robot r to a goal node (any time). Throws std::out_of_range on a bad index or node.
  void setRobotGoal(std::size_t r, topology::NodeIndex goal);

  // Static clutter (bed posts) in the map frame.
  const std::vector<Circle>& posts() const { return posts_; }
  // The scene the lasers of robot r see now (legs of every picker, posts, other robots' footprints).
  LaserScene laserScene(std::size_t r) const;

 private:
  void internalStep(double dt);
  void fireSensors(SimOutputs& out);
  void callWhenTraysFull(SimOutputs& out);
  void buildPosts();

  const topology::TopologicalMap* map_;
  SimConfig config_;
  LaneLayout layout_;
  core::GeodeticDatum datum_;
  double time_ = 0.0;
  std::vector<SimulatedPicker> pickers_;
  std::vector<GnssErrorModel> gnss_;
  std::vector<bool> waiting_;              // the call scenario: picker i called and waits
  std::vector<double> tray_full_at_;       // s: when picker i's trays are full next
  std::vector<std::mt19937_64> tray_rng_;  // per picker: tray times and reported rows
  std::vector<SimulatedRobot> robots_;
  std::vector<Circle> posts_;
  struct SensorStreams;
  std::vector<std::unique_ptr<SensorStreams>> streams_;  // per robot
  std::uint64_t gnss_tick_ = 0, laser_tick_ = 0, rfid_tick_ = 0, uwb_tick_ = 0, camera_tick_ = 0;
};

// SplitMix64 of (seed, stream): independent seeds for the simulator's generators.
std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t stream);

}  // namespace sim
}  // namespace picker_localisation
