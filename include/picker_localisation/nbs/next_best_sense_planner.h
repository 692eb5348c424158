// Next-Best-Sense planner (Navigate-and-Seek Sec. V): candidate robot goals on graph nodes, four criteria per
// candidate, min-max normalisation, the discrete Choquet integral of Eq. 13, argmax. The EstimatedNode policy
// of Sec. VI-B is a second policy of the same planner. Fleet coordination: see planFleet(). ROS-free.
//
// Criteria of a candidate node c for a robot at node r (raw values; see README docs/readme/nbs.md):
//  travel_distance [m], cost:   graph path length r -> c (Dijkstra on the undirected motion graph).
//  sensing_time [s], cost:      expected duration of the sensing operation at c: the robot senses until a tag
//                               is read or max_sensing_time elapses. A tag within read_range is read at the
//                               Poisson rate r = -ln(1 - p_detect) / max_sensing_time (so it is read within
//                               the window with probability p_detect); with q(c) = P(at least one picker
//                               within read_range of c) under the predicted beliefs, ST = min_sensing_time +
//                               q (1 - e^{-r T}) / r + (1 - q) T,  T = max_sensing_time.
//  rfid_gain [nats], benefit:   expected entropy reduction of the pickers' beliefs by the RFID sensing
//                               operation:
//                               sum_k w_k [H(b_k) - P_k(read) H(b_k | read) - P_k(no read) H(b_k | no read)],
//                               b_k the belief of picker k predicted to the arrival time (travel time
//                               = travel_distance / speed), the posteriors from the BeliefSource what-if with
//                               the RFID observations rfid_ranging would produce: read L(n) = 1 within
//                               read_range of c, no read L(n) = 1 - p_detect within read_range and 1
//                               elsewhere; P_k(read) = p_detect * b_k(read region). w_k = 1, or
//                               claimed_picker_weight when another robot of higher priority already serves
//                               picker k, times the picker's call-due weight (TrayClock: pickers whose
//                               trays are nearly full weigh up to 1 + call_due_weight).
//  battery [fraction], benefit: expected battery level after driving to c and sensing there (EnergyModel).
// Candidates are the nodes reachable from r, optionally limited to horizon_hops hops and / or horizon_m
// metres, minus the goals claimed by higher-priority robots (and nodes within claim_exclusion_hops of them),
// minus the nodes whose battery level on arrival would fall below energy.reserve. The robot's own node is a
// candidate (stay and sense).
#pragma once

#include <yaml-cpp/yaml.h>

#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/nbs/belief_source.h"
#include "picker_localisation/nbs/choquet.h"
#include "picker_localisation/nbs/tray_clock.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace nbs {

enum class Policy { kNextBestSense, kEstimatedNode };
const char* toString(Policy p);                 // "nbs" | "estimated_node"
Policy policyFromString(const std::string& s);  // throws std::invalid_argument

// Criterion order of every criteria vector, FuzzyMeasure and README table.
enum Criterion : std::size_t {
  kTravelDistance = 0,
  kSensingTime = 1,
  kRfidGain = 2,
  kBattery = 3,
  kNumCriteria = 4
};
const std::vector<std::string>& criterionNames();  // travel_distance, sensing_time, rfid_gain, battery

// The RFID sensing the planner expects at a candidate; keep read_range / p_detect equal to rfid_ranging's
// RfidModelOptions so the hypothetical observations are the ones the tracker will really receive.
struct RfidSensingModel {
  double read_range = 3.0;        // m, radius of the read region around the robot (both antennas together)
  double p_detect = 0.7;          // probability that a tag inside the region is read within max_sensing_time
  double min_sensing_time = 1.0;  // s, fixed cost of a stop (settling, one inventory round)
  double max_sensing_time = 5.0;  // s, the robot gives up sensing after this long without a read
  double readRate() const;        // 1/s, Poisson rate r of the header comment
  // Expected sensing time given q = P(some picker within read_range), s.
  double expectedSensingTime(double q) const;
};

// Energy of driving and sensing (a Thorvald-size robot on a 48 V pack; see docs/readme/nbs.md):
//   E = drive_energy_per_m * d + base_power * (d / speed + t_sense) + sensing_power * t_sense   [J]
//   battery after = level - E / capacity.
struct EnergyModel {
  double capacity = 3.6e6;          // J (1 kWh)
  double drive_energy_per_m = 150;  // J/m, traction at walking speed on grass
  double base_power = 60.0;         // W, computers and sensors, always on
  double sensing_power = 10.0;      // W, RFID reader transmitting
  double speed = 1.0;               // m/s, mean driving speed along the graph (also sets the travel time)
  double reserve = 0.1;             // fraction: candidates that would leave less are infeasible
  double energy(double distance, double sensing_time) const;  // J
  double levelAfter(double level, double distance, double sensing_time) const;
};

struct PlannerConfig {
  Policy policy = Policy::kNextBestSense;
  std::vector<double> weights{0.3, 0.1, 0.35, 0.25};  // Table I: TD, ST, RFID, BS (criterion order)
  // Pair interactions of the fuzzy measure (FuzzyMeasure::fromWeights). Defaults: RFID gain with travel
  // distance are synergic (an informative node that is also near is worth more than either), travel distance
  // with battery are redundant (battery is mostly distance); the two cancel on the full set.
  std::vector<CriterionInteraction> interactions{{kRfidGain, kTravelDistance, 0.1},
                                                 {kTravelDistance, kBattery, -0.1}};
  int horizon_hops = 0;           // candidates at most this many hops away (0: no limit)
  double horizon_m = 0.0;         // candidates at most this path length away, m (0: no limit)
  double horizon_bucket = 2.0;    // s, arrival times are rounded to this step to share predictions
  double planning_latency = 0.0;  // s added to every arrival time (belief age at planning)
  RfidSensingModel rfid;
  EnergyModel energy;
  double claimed_picker_weight = 0.0;  // w_k of a picker served by a higher-priority robot
  int claim_exclusion_hops = 0;        // nodes within this many hops of a claimed goal are excluded too
  // Call-aware idle positioning (TrayClock): a picker's w_k is multiplied by
  // 1 + call_due_weight * min(1, time since its trays were emptied / tray_time_mean). 0: off.
  double call_due_weight = 0.0;
  double tray_time_mean = 360.0;  // s, the farm's mean time to fill a picker's trays
  std::string target_picker;  // estimated_node: picker to reach ("" = first unclaimed, in input order)

  FuzzyMeasure measure() const;  // throws std::invalid_argument on bad weights / interactions
  std::string validate() const;  // "" when valid

  // Keys as config/nbs.yaml (missing keys keep the defaults). Throws std::runtime_error naming the key. With
  // `unknown`, one message per key that is not the planner's (yamlKeys(), and the sub-keys of weights,
  // rfid, energy) is appended, naming the closest known key. The nbs_planner node's own keys, which
  // config/nbs.yaml holds too: NbsPlannerNodeOptions.
  static PlannerConfig fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static PlannerConfig fromYamlFile(const std::string& path, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();
  // One message per key of `node` that is neither the planner's nor in `also_known`, and per unknown key of
  // the weights, rfid and energy sections, each naming the closest known key.
  static std::vector<std::string> unknownKeys(const YAML::Node& node,
                                              const std::vector<std::string>& also_known);
};

// A goal taken by another robot.
struct Claim {
  std::string robot_id;
  topology::NodeIndex node = topology::kInvalidNode;
  std::string picker_id;  // picker that robot serves ("" none)
};

struct Candidate {
  topology::NodeIndex node = topology::kInvalidNode;
  std::vector<double> raw;         // criterion values in their units (criterionNames() order)
  std::vector<double> normalised;  // min-max normalised utilities in [0, 1]
  double utility = 0.0;            // Choquet integral (Eq. 13), [0, 1]
  std::string target_picker;  // picker contributing most to rfid_gain (nbs) or the target (estimated_node)
};

struct PlanResult {
  Policy policy = Policy::kNextBestSense;
  std::vector<std::string> criteria;  // names of the entries of Candidate::raw / normalised
  std::vector<Candidate> ranked;      // best first; empty when there is no feasible candidate
  std::string problem;                // why ranked is empty ("" otherwise)
  std::size_t what_if_queries = 0;    // BeliefSource::posterior calls made
  bool ok() const { return !ranked.empty(); }
};

class NextBestSensePlanner {
 public:
  // Throws std::invalid_argument when the configuration is invalid or the map is null.
  NextBestSensePlanner(std::shared_ptr<const topology::TopologicalMap> map, PlannerConfig config);

  // Ranks the candidate goals of a robot at robot_node with battery_level in [0, 1]. `pickers` are what-if
  // views of the pickers' trackers (non-owning, may be empty: rfid_gain is then 0 everywhere); `claims` are
  // the goals of the robots with higher priority (see planFleet); `picker_weights` multiply the pickers' w_k
  // (TrayClock::weights; a picker not in it: 1).
  PlanResult plan(topology::NodeIndex robot_node, double battery_level,
                  const std::vector<BeliefSource*>& pickers, const std::vector<Claim>& claims = {},
                  const PickerWeights& picker_weights = {}) const;

  const PlannerConfig& config() const { return config_; }
  const topology::TopologicalMap& map() const { return *map_; }

 private:
  PlanResult planNextBestSense(topology::NodeIndex robot, double battery,
                               const std::vector<BeliefSource*>& pickers, const std::vector<Claim>& claims,
                               const PickerWeights& picker_weights) const;
  PlanResult planEstimatedNode(topology::NodeIndex robot, double battery,
                               const std::vector<BeliefSource*>& pickers,
                               const std::vector<Claim>& claims) const;
  double expectedRfidGain(BeliefSource& source, topology::NodeIndex c,
                          const std::vector<topology::NodeIndex>& region, const NodeMasses& prior,
                          double horizon, std::size_t* what_if_queries) const;
  std::vector<topology::NodeIndex> candidateNodes(topology::NodeIndex robot,
                                                  const std::vector<Claim>& claims) const;

  std::shared_ptr<const topology::TopologicalMap> map_;
  PlannerConfig config_;
  FuzzyMeasure measure_;
};

// Fleet rule (documented in docs/readme/nbs.md): robots have priority in robot-id order (natural order, so
// robot_2 < robot_10). Each robot plans with the goals of every higher-priority robot as claims: their goal
// nodes are excluded from its candidates and the pickers they serve weigh claimed_picker_weight in its RFID
// gain (estimated_node: it targets the first picker nobody claimed). Hence two robots never get the same
// goal, and a lower-priority robot never makes a higher-priority one change its plan (no oscillation).
struct RobotState {
  std::string robot_id;
  topology::NodeIndex node = topology::kInvalidNode;
  double battery_level = 1.0;
};
struct FleetGoal {
  std::string robot_id;
  PlanResult plan;  // plan.ranked.front() is the goal when plan.ok()
};
// Plans every robot in priority order; the result is in priority order too.
std::vector<FleetGoal> planFleet(const NextBestSensePlanner& planner, std::vector<RobotState> robots,
                                 const std::vector<BeliefSource*>& pickers);
// Natural order of robot ids ("robot_2" before "robot_10"); true when a has priority over b.
bool robotHasPriority(const std::string& a, const std::string& b);
// The claims robot_id must respect among all published goals: those of robots with priority over it.
std::vector<Claim> claimsFor(const std::string& robot_id, const std::vector<Claim>& all_goals);

}  // namespace nbs
}  // namespace picker_localisation
