#include "picker_localisation/nbs/next_best_sense_planner.h"

#include "picker_localisation/core/yaml_file.h"
#include "picker_localisation/core/yaml_keys.h"

#include <Eigen/LU>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <queue>
#include <set>
#include <sstream>
#include <stdexcept>

namespace picker_localisation {
namespace nbs {

using topology::kInvalidNode;
using topology::NodeIndex;
using topology::TopologicalMap;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNegligibleMass = 1e-9;  // belief mass in a read region below this gives no gain

std::vector<std::string> splitNatural(const std::string& s) {
  std::vector<std::string> parts;
  std::size_t i = 0;
  while (i < s.size()) {
    std::size_t j = i;
    const bool digit = std::isdigit(static_cast<unsigned char>(s[i]));
    while (j < s.size() && static_cast<bool>(std::isdigit(static_cast<unsigned char>(s[j]))) == digit) ++j;
    parts.push_back(s.substr(i, j - i));
    i = j;
  }
  return parts;
}

void sortRanked(std::vector<Candidate>& c, const std::vector<double>& tie_distance) {
  std::sort(c.begin(), c.end(), [&](const Candidate& a, const Candidate& b) {
    if (a.utility != b.utility) return a.utility > b.utility;
    if (tie_distance[a.node] != tie_distance[b.node]) return tie_distance[a.node] < tie_distance[b.node];
    return a.node < b.node;
  });
}

template <typename T>
void readKey(const YAML::Node& node, const std::string& key, T& value, const std::string& prefix = "") {
  if (!node || !node[key]) return;
  try {
    value = node[key].as<T>();
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("nbs config: bad value for '" + prefix + key + "': " + e.what());
  }
}

std::size_t criterionIndex(const std::string& name) {
  const auto& names = criterionNames();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return i;
  throw std::runtime_error("nbs config: unknown criterion '" + name +
                           "' (expected travel_distance, sensing_time, rfid_gain or battery)");
}

}  // namespace

const char* toString(Policy p) {
  return p == Policy::kEstimatedNode ? "estimated_node" : "nbs";
}

Policy policyFromString(const std::string& s) {
  if (s == "nbs" || s == "next_best_sense") return Policy::kNextBestSense;
  if (s == "estimated_node") return Policy::kEstimatedNode;
  throw std::invalid_argument("unknown planner policy '" + s + "' (expected nbs or estimated_node)");
}

const std::vector<std::string>& criterionNames() {
  static const std::vector<std::string> names{"travel_distance", "sensing_time", "rfid_gain", "battery"};
  return names;
}

double RfidSensingModel::readRate() const {
  return -std::log(1.0 - p_detect) / max_sensing_time;
}

double RfidSensingModel::expectedSensingTime(double q) const {
  q = std::clamp(q, 0.0, 1.0);
  const double r = readRate();
  const double t = max_sensing_time;
  // E[min(T_read, t)] for T_read ~ Exp(r) is (1 - e^{-r t}) / r.
  return min_sensing_time + q * (1.0 - std::exp(-r * t)) / r + (1.0 - q) * t;
}

double EnergyModel::energy(double distance, double sensing_time) const {
  return drive_energy_per_m * distance + base_power * (distance / speed + sensing_time) +
         sensing_power * sensing_time;
}

double EnergyModel::levelAfter(double level, double distance, double sensing_time) const {
  return level - energy(distance, sensing_time) / capacity;
}

FuzzyMeasure PlannerConfig::measure() const {
  if (weights.size() != kNumCriteria)
    throw std::invalid_argument("nbs: need 4 weights (travel_distance, sensing_time, rfid_gain, battery)");
  return FuzzyMeasure::fromWeights(weights, interactions);
}

std::string PlannerConfig::validate() const {
  try {
    measure();
  } catch (const std::exception& e) {
    return e.what();
  }
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (horizon_hops < 0) return "horizon_hops must be >= 0";
  if (!(horizon_m >= 0.0)) return "horizon_m must be >= 0";
  if (!positive(horizon_bucket)) return "horizon_bucket must be > 0";
  if (!(planning_latency >= 0.0)) return "planning_latency must be >= 0";
  if (!positive(rfid.read_range)) return "rfid/read_range must be > 0";
  if (!(rfid.p_detect > 0.0 && rfid.p_detect < 1.0)) return "rfid/p_detect must be in (0, 1)";
  if (!(rfid.min_sensing_time >= 0.0)) return "rfid/min_sensing_time must be >= 0";
  if (!positive(rfid.max_sensing_time)) return "rfid/max_sensing_time must be > 0";
  if (!positive(energy.capacity)) return "energy/capacity must be > 0";
  if (!positive(energy.speed)) return "energy/speed must be > 0";
  if (!(energy.drive_energy_per_m >= 0.0 && energy.base_power >= 0.0 && energy.sensing_power >= 0.0))
    return "energy: drive_energy_per_m, base_power and sensing_power must be >= 0";
  if (!(energy.reserve >= 0.0 && energy.reserve < 1.0)) return "energy/reserve must be in [0, 1)";
  if (!(claimed_picker_weight >= 0.0 && claimed_picker_weight <= 1.0))
    return "claimed_picker_weight must be in [0, 1]";
  if (claim_exclusion_hops < 0) return "claim_exclusion_hops must be >= 0";
  if (!(call_due_weight >= 0.0) || !std::isfinite(call_due_weight))
    return "call_due_weight must be finite and >= 0";
  if (!positive(tray_time_mean) || !std::isfinite(tray_time_mean)) return "tray_time_mean must be > 0";
  return "";
}

const std::vector<std::string>& PlannerConfig::yamlKeys() {
  // Kept in rows (clang-format would put one key per line).
  // clang-format off
  static const std::vector<std::string> keys = {
      "policy", "weights", "interactions", "horizon_hops", "horizon_m", "horizon_bucket", "planning_latency", "rfid",
      "energy", "claimed_picker_weight", "claim_exclusion_hops", "target_picker", "call_due_weight", "tray_time_mean"};
  // clang-format on
  return keys;
}

std::vector<std::string> PlannerConfig::unknownKeys(const YAML::Node& node,
                                                    const std::vector<std::string>& also_known) {
  std::vector<std::string> out;
  if (!node || !node.IsMap()) return out;
  std::vector<std::string> known = yamlKeys();
  known.insert(known.end(), also_known.begin(), also_known.end());
  for (auto& m : core::unknownKeys(node, known, "nbs config")) out.push_back(std::move(m));
  const std::vector<std::pair<const char*, std::vector<std::string>>> sections = {
      {"weights", criterionNames()},
      {"rfid", {"read_range", "p_detect", "min_sensing_time", "max_sensing_time"}},
      {"energy", {"capacity", "drive_energy_per_m", "base_power", "sensing_power", "speed", "reserve"}}};
  for (const auto& [section, keys] : sections)
    if (node[section])
      for (auto& m : core::unknownKeys(node[section], keys, std::string("nbs config: ") + section))
        out.push_back(std::move(m));
  return out;
}

PlannerConfig PlannerConfig::fromYaml(const YAML::Node& node, std::vector<std::string>* unknown) {
  PlannerConfig c;
  if (!node) return c;
  if (unknown)
    for (auto& m : unknownKeys(node, {})) unknown->push_back(std::move(m));
  if (node["policy"]) {
    try {
      c.policy = policyFromString(node["policy"].as<std::string>());
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string("nbs config: bad value for 'policy': ") + e.what());
    }
  }
  if (const YAML::Node w = node["weights"]) {
    for (std::size_t i = 0; i < kNumCriteria; ++i) readKey(w, criterionNames()[i], c.weights[i], "weights/");
  }
  if (const YAML::Node inter = node["interactions"]) {
    c.interactions.clear();
    if (!inter.IsSequence()) throw std::runtime_error("nbs config: 'interactions' must be a list");
    for (const YAML::Node& item : inter) {
      if (!item["criteria"] || !item["criteria"].IsSequence() || item["criteria"].size() != 2 ||
          !item["bonus"])
        throw std::runtime_error("nbs config: each entry of 'interactions' needs criteria: [a, b] and bonus");
      CriterionInteraction ci;
      ci.a = criterionIndex(item["criteria"][0].as<std::string>());
      ci.b = criterionIndex(item["criteria"][1].as<std::string>());
      readKey(item, "bonus", ci.bonus, "interactions/");
      c.interactions.push_back(ci);
    }
  }
  readKey(node, "horizon_hops", c.horizon_hops);
  readKey(node, "horizon_m", c.horizon_m);
  readKey(node, "horizon_bucket", c.horizon_bucket);
  readKey(node, "planning_latency", c.planning_latency);
  if (const YAML::Node r = node["rfid"]) {
    readKey(r, "read_range", c.rfid.read_range, "rfid/");
    readKey(r, "p_detect", c.rfid.p_detect, "rfid/");
    readKey(r, "min_sensing_time", c.rfid.min_sensing_time, "rfid/");
    readKey(r, "max_sensing_time", c.rfid.max_sensing_time, "rfid/");
  }
  if (const YAML::Node e = node["energy"]) {
    readKey(e, "capacity", c.energy.capacity, "energy/");
    readKey(e, "drive_energy_per_m", c.energy.drive_energy_per_m, "energy/");
    readKey(e, "base_power", c.energy.base_power, "energy/");
    readKey(e, "sensing_power", c.energy.sensing_power, "energy/");
    readKey(e, "speed", c.energy.speed, "energy/");
    readKey(e, "reserve", c.energy.reserve, "energy/");
  }
  readKey(node, "claimed_picker_weight", c.claimed_picker_weight);
  readKey(node, "claim_exclusion_hops", c.claim_exclusion_hops);
  readKey(node, "target_picker", c.target_picker);
  readKey(node, "call_due_weight", c.call_due_weight);
  readKey(node, "tray_time_mean", c.tray_time_mean);
  const std::string problem = c.validate();
  if (!problem.empty()) throw std::runtime_error("nbs config: " + problem);
  return c;
}

PlannerConfig PlannerConfig::fromYamlFile(const std::string& path, std::vector<std::string>* unknown) {
  return core::parseYamlFile(path, [unknown](const YAML::Node& root) {
    return fromYaml(root["nbs_planner"] ? root["nbs_planner"] : root, unknown);
  });
}

NextBestSensePlanner::NextBestSensePlanner(std::shared_ptr<const TopologicalMap> map, PlannerConfig config)
    : map_(std::move(map)), config_(std::move(config)), measure_(FuzzyMeasure::fromWeights({1.0})) {
  if (!map_) throw std::invalid_argument("NextBestSensePlanner: null map");
  const std::string problem = config_.validate();
  if (!problem.empty()) throw std::invalid_argument("NextBestSensePlanner: " + problem);
  measure_ = config_.measure();
}

std::vector<NodeIndex> NextBestSensePlanner::candidateNodes(NodeIndex robot,
                                                            const std::vector<Claim>& claims) const {
  const std::size_t n = map_->numNodes();
  std::vector<bool> excluded(n, false);
  for (const Claim& c : claims) {
    if (c.node >= n) continue;
    if (config_.claim_exclusion_hops == 0) {
      excluded[c.node] = true;
      continue;
    }
    const auto hops = map_->hopDistances(c.node);
    for (std::size_t m = 0; m < n; ++m)
      if ((*hops)[m] >= 0 && (*hops)[m] <= config_.claim_exclusion_hops) excluded[m] = true;
  }
  std::vector<NodeIndex> out;
  const auto hops = map_->hopDistances(robot);
  for (std::size_t m = 0; m < n; ++m) {
    if (excluded[m] || (*hops)[m] < 0) continue;
    if (config_.horizon_hops > 0 && (*hops)[m] > config_.horizon_hops) continue;
    out.push_back(static_cast<NodeIndex>(m));
  }
  return out;
}

PlanResult NextBestSensePlanner::plan(NodeIndex robot_node, double battery_level,
                                      const std::vector<BeliefSource*>& pickers,
                                      const std::vector<Claim>& claims,
                                      const PickerWeights& picker_weights) const {
  PlanResult result;
  result.policy = config_.policy;
  if (robot_node >= map_->numNodes()) {
    result.problem = "robot node " + std::to_string(robot_node) + " is not a node of the map";
    return result;
  }
  if (!std::isfinite(battery_level)) {
    result.problem = "battery level is not finite";
    return result;
  }
  return config_.policy == Policy::kEstimatedNode
             ? planEstimatedNode(robot_node, battery_level, pickers, claims)
             : planNextBestSense(robot_node, battery_level, pickers, claims, picker_weights);
}

// One picker's expected entropy reduction by a sensing stop at c (the rfid_gain criterion, Polvara et al.
// 2021 Sec. V): H(b) - P(read) H(b | read) - P(no read) H(b | no read), with the observations rfid_ranging
// would report (identifying; read: L(n) = 1 in the read region, no read: 1 - p_detect there and 1
// elsewhere) and P(read) = p_detect b(region). Clamped at 0: it is >= 0 in expectation, particle noise can
// dip below.
double NextBestSensePlanner::expectedRfidGain(BeliefSource& source, NodeIndex c,
                                              const std::vector<NodeIndex>& region, const NodeMasses& prior,
                                              double horizon, std::size_t* what_if_queries) const {
  const std::size_t n = map_->numNodes();
  const double p_detect = config_.rfid.p_detect;
  double in_region = 0.0;
  for (NodeIndex m : region) in_region += prior[m];
  const double p_read = std::clamp(p_detect * in_region, 0.0, 1.0);
  core::Observation read;
  read.sensor = "rfid";
  read.picker_id = source.pickerId();
  read.identifying = true;
  read.position = map_->position2d(c);
  core::Observation no_read = read;
  read.nodes = region;
  read.likelihood.assign(region.size(), 1.0);
  core::setLikelihoodOverEveryNode(no_read, n);
  for (NodeIndex m : region) no_read.likelihood[m] = 1.0 - p_detect;
  const NodeMasses post_read = source.posterior(horizon, read);
  const NodeMasses post_none = source.posterior(horizon, no_read);
  if (what_if_queries) *what_if_queries += 2;
  if (post_read.size() != n || post_none.size() != n) return 0.0;
  return std::max(0.0, entropy(prior) - p_read * entropy(post_read) - (1.0 - p_read) * entropy(post_none));
}

PlanResult NextBestSensePlanner::planNextBestSense(NodeIndex robot, double battery,
                                                   const std::vector<BeliefSource*>& pickers,
                                                   const std::vector<Claim>& claims,
                                                   const PickerWeights& picker_weights) const {
  PlanResult result;
  result.policy = Policy::kNextBestSense;
  result.criteria = criterionNames();
  const std::size_t n = map_->numNodes();
  const std::vector<double> dist = map_->pathLengthsFrom(robot);
  std::vector<NodeIndex> nodes = candidateNodes(robot, claims);
  if (config_.horizon_m > 0.0)
    nodes.erase(
        std::remove_if(nodes.begin(), nodes.end(), [&](NodeIndex c) { return dist[c] > config_.horizon_m; }),
        nodes.end());
  if (nodes.empty()) {
    result.problem = "no reachable unclaimed candidate node";
    return result;
  }

  // Picker weights: pickers served by a higher-priority robot count claimed_picker_weight, times the
  // call-due weight (TrayClock).
  std::set<std::string> claimed_pickers;
  for (const Claim& c : claims)
    if (!c.picker_id.empty()) claimed_pickers.insert(c.picker_id);
  struct PickerState {
    BeliefSource* source = nullptr;
    double weight = 1.0;
    std::map<long, NodeMasses> predicted;  // horizon bucket -> predicted masses
  };
  std::vector<PickerState> states;
  for (BeliefSource* s : pickers) {
    if (!s) continue;
    PickerState p;
    p.source = s;
    p.weight = claimed_pickers.count(s->pickerId()) ? config_.claimed_picker_weight : 1.0;
    if (const auto w = picker_weights.find(s->pickerId()); w != picker_weights.end()) p.weight *= w->second;
    states.push_back(std::move(p));
  }

  const RfidSensingModel& rfid = config_.rfid;
  std::vector<Candidate> candidates;
  candidates.reserve(nodes.size());
  std::size_t infeasible = 0;
  for (NodeIndex c : nodes) {
    const double travel_time = dist[c] / config_.energy.speed + config_.planning_latency;
    const long bucket = std::lround(travel_time / config_.horizon_bucket);
    const double horizon = static_cast<double>(bucket) * config_.horizon_bucket;
    const std::vector<NodeIndex> region = map_->nodesWithin(map_->position2d(c), rfid.read_range);
    double gain = 0.0, best_gain = 0.0, p_none_in_range = 1.0;
    std::string best_picker;
    for (PickerState& p : states) {
      auto it = p.predicted.find(bucket);
      if (it == p.predicted.end()) it = p.predicted.emplace(bucket, p.source->predicted(horizon)).first;
      const NodeMasses& prior = it->second;
      if (prior.size() != n) continue;  // no belief for this picker yet
      double in_region = 0.0;
      for (NodeIndex m : region) in_region += prior[m];
      in_region = std::clamp(in_region, 0.0, 1.0);
      p_none_in_range *= 1.0 - in_region;
      if (in_region < kNegligibleMass || !(p.weight > 0.0)) continue;
      const double picker_gain =
          p.weight * expectedRfidGain(*p.source, c, region, prior, horizon, &result.what_if_queries);
      gain += picker_gain;
      if (picker_gain > best_gain) {
        best_gain = picker_gain;
        best_picker = p.source->pickerId();
      }
    }
    const double sensing_time = rfid.expectedSensingTime(1.0 - p_none_in_range);
    const double battery_after = config_.energy.levelAfter(battery, dist[c], sensing_time);
    if (battery_after < config_.energy.reserve) {
      ++infeasible;
      continue;
    }
    Candidate cand;
    cand.node = c;
    cand.raw = {dist[c], sensing_time, gain, battery_after};
    cand.target_picker = best_picker;
    candidates.push_back(std::move(cand));
  }
  if (candidates.empty()) {
    result.problem = "every candidate would leave the battery below the reserve (" +
                     std::to_string(infeasible) + " candidates)";
    return result;
  }

  // Min-max normalisation per criterion over the feasible candidates.
  const bool benefit[kNumCriteria] = {false, false, true, true};
  std::vector<double> column(candidates.size());
  for (auto& cand : candidates) cand.normalised.assign(kNumCriteria, 0.0);
  for (std::size_t k = 0; k < kNumCriteria; ++k) {
    for (std::size_t i = 0; i < candidates.size(); ++i) column[i] = candidates[i].raw[k];
    const std::vector<double> u = minMaxNormalise(column, benefit[k]);
    for (std::size_t i = 0; i < candidates.size(); ++i) candidates[i].normalised[k] = u[i];
  }
  for (auto& cand : candidates) cand.utility = choquetIntegral(cand.normalised, measure_);
  sortRanked(candidates, dist);
  result.ranked = std::move(candidates);
  return result;
}

PlanResult NextBestSensePlanner::planEstimatedNode(NodeIndex robot, double battery,
                                                   const std::vector<BeliefSource*>& pickers,
                                                   const std::vector<Claim>& claims) const {
  PlanResult result;
  result.policy = Policy::kEstimatedNode;
  result.criteria = {"distance_to_estimate"};
  std::set<std::string> claimed_pickers;
  for (const Claim& c : claims)
    if (!c.picker_id.empty()) claimed_pickers.insert(c.picker_id);
  BeliefSource* target = nullptr;
  for (BeliefSource* s : pickers) {
    if (!s || s->estimatedNode() >= map_->numNodes()) continue;
    if (!config_.target_picker.empty()) {
      if (s->pickerId() == config_.target_picker) target = s;
      continue;
    }
    if (!target) target = s;  // fallback when every picker is claimed
    if (!claimed_pickers.count(s->pickerId())) {
      target = s;
      break;
    }
  }
  if (!target) {
    result.problem = config_.target_picker.empty()
                         ? "no picker has a belief yet"
                         : "target picker '" + config_.target_picker + "' has no belief yet";
    return result;
  }
  // The estimated node itself, or, when another robot claimed it, the nearest unclaimed node to it. Every
  // reachable node is ranked by its path length to the estimate (the horizon does not apply: the policy goes
  // wherever the estimate is).
  const NodeIndex estimate = target->estimatedNode();
  const std::vector<double> to_estimate = map_->pathLengthsFrom(estimate);
  const std::vector<double> from_robot = map_->pathLengthsFrom(robot);
  std::vector<NodeIndex> nodes;
  {
    const auto hops = map_->hopDistances(robot);
    std::set<NodeIndex> excluded;
    for (const Claim& c : claims)
      if (c.node < map_->numNodes()) excluded.insert(c.node);
    for (std::size_t m = 0; m < map_->numNodes(); ++m)
      if ((*hops)[m] >= 0 && std::isfinite(to_estimate[m]) && !excluded.count(static_cast<NodeIndex>(m)))
        nodes.push_back(static_cast<NodeIndex>(m));
  }
  if (nodes.empty()) {
    result.problem = "the estimated node of '" + target->pickerId() + "' is not reachable from the robot";
    return result;
  }
  std::vector<double> raw(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) raw[i] = to_estimate[nodes[i]];
  const std::vector<double> u = minMaxNormalise(raw, false);
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    Candidate c;
    c.node = nodes[i];
    c.raw = {raw[i]};
    c.normalised = {u[i]};
    c.utility = u[i];
    c.target_picker = target->pickerId();
    result.ranked.push_back(std::move(c));
  }
  sortRanked(result.ranked, from_robot);
  (void)battery;
  return result;
}

bool robotHasPriority(const std::string& a, const std::string& b) {
  const std::vector<std::string> pa = splitNatural(a), pb = splitNatural(b);
  for (std::size_t i = 0; i < std::min(pa.size(), pb.size()); ++i) {
    if (pa[i] == pb[i]) continue;
    const bool da = std::isdigit(static_cast<unsigned char>(pa[i][0]));
    const bool db = std::isdigit(static_cast<unsigned char>(pb[i][0]));
    if (da && db) {
      const std::string sa = pa[i].substr(std::min(pa[i].find_first_not_of('0'), pa[i].size() - 1));
      const std::string sb = pb[i].substr(std::min(pb[i].find_first_not_of('0'), pb[i].size() - 1));
      if (sa.size() != sb.size()) return sa.size() < sb.size();
      if (sa != sb) return sa < sb;
      return pa[i] < pb[i];
    }
    return pa[i] < pb[i];
  }
  return pa.size() < pb.size();
}

std::vector<Claim> claimsFor(const std::string& robot_id, const std::vector<Claim>& all_goals) {
  std::vector<Claim> out;
  for (const Claim& c : all_goals)
    if (c.robot_id != robot_id && robotHasPriority(c.robot_id, robot_id)) out.push_back(c);
  return out;
}

std::vector<FleetGoal> planFleet(const NextBestSensePlanner& planner, std::vector<RobotState> robots,
                                 const std::vector<BeliefSource*>& pickers) {
  std::stable_sort(robots.begin(), robots.end(), [](const RobotState& a, const RobotState& b) {
    return robotHasPriority(a.robot_id, b.robot_id);
  });
  std::vector<FleetGoal> goals;
  std::vector<Claim> claims;
  for (const RobotState& r : robots) {
    FleetGoal g;
    g.robot_id = r.robot_id;
    g.plan = planner.plan(r.node, r.battery_level, pickers, claims);
    if (g.plan.ok())
      claims.push_back({r.robot_id, g.plan.ranked.front().node, g.plan.ranked.front().target_picker});
    goals.push_back(std::move(g));
  }
  return goals;
}

}  // namespace nbs
}  // namespace picker_localisation
