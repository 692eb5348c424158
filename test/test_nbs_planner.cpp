// Next-Best-Sense planner on synthetic polytunnels with static beliefs (StaticBeliefSource, exact Bayes): the
// criteria against hand-computed values, the preference for an uncertain picker, the fleet rule,
// EstimatedNode.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "nbs_test_maps.h"
#include "picker_localisation/nbs/next_best_sense_planner.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/LU>

using namespace picker_localisation;
using namespace picker_localisation::nbs;
using nbs_test::wideTunnels;
using topology::NodeIndex;

namespace {

NodeIndex laneNode(const topology::TopologicalMap& map, int lane, int k) {
  return map.laneNodes(map.lane(*map.index("r" + std::to_string(lane) + "_0")))[static_cast<std::size_t>(k)];
}

NodeMasses uniformOver(const topology::TopologicalMap& map, const std::vector<NodeIndex>& nodes) {
  NodeMasses m(map.numNodes(), 0.0);
  for (NodeIndex n : nodes) m[n] = 1.0 / static_cast<double>(nodes.size());
  return m;
}

const Candidate* find(const PlanResult& r, NodeIndex n) {
  for (const Candidate& c : r.ranked)
    if (c.node == n) return &c;
  return nullptr;
}

}  // namespace

TEST(NbsPlanner, RfidGainMatchesHandComputation) {
  auto map = wideTunnels();
  // Picker on one of two nodes 9 m apart in lane 0; a candidate at the first sees only it.
  const NodeIndex a = laneNode(*map, 0, 2), b = laneNode(*map, 0, 5);
  ASSERT_NEAR(map->distance(a, b), 9.0, 1e-9);
  StaticBeliefSource picker("p", uniformOver(*map, {a, b}));
  PlannerConfig cfg;
  NextBestSensePlanner planner(map, cfg);
  const PlanResult r = planner.plan(a, 1.0, {&picker});
  ASSERT_TRUE(r.ok()) << r.problem;
  const Candidate* at_a = find(r, a);
  ASSERT_NE(at_a, nullptr);
  const double p = cfg.rfid.p_detect;
  // Read: certain (H = 0). No read: masses (0.5 (1 - p), 0.5) normalised.
  const double q0 = (1 - p) / (2 - p), q1 = 1 / (2 - p);
  const double h_none = -q0 * std::log(q0) - q1 * std::log(q1);
  const double expected = std::log(2.0) - (1 - 0.5 * p) * h_none;
  EXPECT_NEAR(at_a->raw[kRfidGain], expected, 1e-12);
  EXPECT_NEAR(at_a->raw[kTravelDistance], 0.0, 1e-12);
  // Sensing time with q = 0.5: min + 0.5 (1 - e^{-rT}) / r + 0.5 T, e^{-rT} = 1 - p.
  const double rate = -std::log(1 - p) / cfg.rfid.max_sensing_time;
  EXPECT_NEAR(at_a->raw[kSensingTime],
              cfg.rfid.min_sensing_time + 0.5 * p / rate + 0.5 * cfg.rfid.max_sensing_time, 1e-12);
  // Battery: nothing driven, only sensing energy.
  const double joules = (cfg.energy.base_power + cfg.energy.sensing_power) * at_a->raw[kSensingTime];
  EXPECT_NEAR(at_a->raw[kBattery], 1.0 - joules / cfg.energy.capacity, 1e-12);
  // A node 3 lanes away sees nothing: no gain, the longest sensing time.
  const Candidate* far = find(r, laneNode(*map, 3, 2));
  ASSERT_NE(far, nullptr);
  EXPECT_DOUBLE_EQ(far->raw[kRfidGain], 0.0);
  EXPECT_NEAR(far->raw[kSensingTime], cfg.rfid.min_sensing_time + cfg.rfid.max_sensing_time, 1e-12);
  EXPECT_NEAR(far->raw[kTravelDistance], map->pathLength(a, far->node), 1e-9);
  // Utilities are the Choquet integral of the normalised criteria, ranked best first.
  for (std::size_t i = 0; i < r.ranked.size(); ++i) {
    EXPECT_NEAR(r.ranked[i].utility, choquetIntegral(r.ranked[i].normalised, cfg.measure()), 1e-12);
    if (i > 0) EXPECT_GE(r.ranked[i - 1].utility, r.ranked[i].utility);
  }
}

TEST(NbsPlanner, PrefersCandidateNearUncertainPicker) {
  auto map = wideTunnels();
  // Confident picker: all mass on one node of lane 0. Uncertain picker: spread over lane 4.
  StaticBeliefSource confident("confident", uniformOver(*map, {laneNode(*map, 0, 5)}));
  StaticBeliefSource uncertain("uncertain",
                               uniformOver(*map, map->laneNodes(map->lane(laneNode(*map, 4, 0)))));
  // The robot on the headland node of lane 2, equally far from both lanes.
  const NodeIndex robot = *map->index("H2");
  NextBestSensePlanner planner(map, PlannerConfig{});
  const PlanResult r = planner.plan(robot, 0.8, {&confident, &uncertain});
  ASSERT_TRUE(r.ok()) << r.problem;
  const Candidate& best = r.ranked.front();
  EXPECT_EQ(map->lane(best.node), map->lane(laneNode(*map, 4, 0))) << map->node(best.node).name;
  EXPECT_EQ(best.target_picker, "uncertain");
  // Mirror nodes (same travel distance): the one by the uncertain picker ranks higher.
  for (int k = 0; k < 10; ++k) {
    const Candidate* near_uncertain = find(r, laneNode(*map, 4, k));
    const Candidate* near_confident = find(r, laneNode(*map, 0, k));
    ASSERT_TRUE(near_uncertain && near_confident);
    ASSERT_NEAR(near_uncertain->raw[kTravelDistance], near_confident->raw[kTravelDistance], 1e-9);
    EXPECT_GT(near_uncertain->utility, near_confident->utility) << "lane node " << k;
    EXPECT_DOUBLE_EQ(near_confident->raw[kRfidGain], 0.0);  // a certain belief cannot lose entropy
  }
}

TEST(NbsPlanner, HorizonAndBatteryReserveLimitCandidates) {
  auto map = wideTunnels();
  StaticBeliefSource picker("p", uniformOver(*map, {laneNode(*map, 1, 3)}));
  const NodeIndex robot = laneNode(*map, 0, 0);
  PlannerConfig cfg;
  cfg.horizon_hops = 2;
  const PlanResult r = NextBestSensePlanner(map, cfg).plan(robot, 1.0, {&picker});
  ASSERT_TRUE(r.ok());
  for (const Candidate& c : r.ranked) EXPECT_LE(map->hopDistance(robot, c.node), 2);
  EXPECT_EQ(r.ranked.size(), 5u);  // itself, r0_1, r0_2, H0, H1
  // Battery: with 0.1 + a little left, only nodes reachable with the reserve intact remain.
  cfg.horizon_hops = 0;
  const NextBestSensePlanner planner(map, cfg);
  const double joules_10m = cfg.energy.energy(10.0, cfg.rfid.min_sensing_time + cfg.rfid.max_sensing_time);
  const PlanResult low =
      planner.plan(robot, cfg.energy.reserve + joules_10m / cfg.energy.capacity, {&picker});
  ASSERT_TRUE(low.ok());
  for (const Candidate& c : low.ranked) {
    EXPECT_GE(c.raw[kBattery], cfg.energy.reserve);
    EXPECT_LE(c.raw[kTravelDistance], 10.0 + 1e-9);
  }
  const PlanResult empty = planner.plan(robot, cfg.energy.reserve * 0.5, {&picker});
  EXPECT_FALSE(empty.ok());
  EXPECT_NE(empty.problem.find("reserve"), std::string::npos);
  EXPECT_FALSE(planner.plan(static_cast<NodeIndex>(map->numNodes()), 1.0, {&picker}).ok());
}

TEST(NbsFleet, TwoRobotsNeverShareAGoal) {
  auto map = wideTunnels();
  StaticBeliefSource uncertain("uncertain",
                               uniformOver(*map, map->laneNodes(map->lane(laneNode(*map, 2, 0)))));
  PlannerConfig cfg;
  const NextBestSensePlanner planner(map, cfg);
  // Both robots on the same node: without coordination they would pick the same goal.
  const NodeIndex start = *map->index("H2");
  const PlanResult alone = planner.plan(start, 1.0, {&uncertain});
  ASSERT_TRUE(alone.ok());
  const auto goals = planFleet(planner, {{"robot_2", start, 1.0}, {"robot_1", start, 1.0}}, {&uncertain});
  ASSERT_EQ(goals.size(), 2u);
  EXPECT_EQ(goals[0].robot_id, "robot_1");  // priority in id order, whatever the input order
  ASSERT_TRUE(goals[0].plan.ok() && goals[1].plan.ok());
  EXPECT_EQ(goals[0].plan.ranked.front().node, alone.ranked.front().node);
  EXPECT_NE(goals[0].plan.ranked.front().node, goals[1].plan.ranked.front().node);
  for (const Candidate& c : goals[1].plan.ranked) EXPECT_NE(c.node, goals[0].plan.ranked.front().node);
  // Claimed pickers: two uncertain pickers, the second robot serves the other one.
  StaticBeliefSource other("other", uniformOver(*map, map->laneNodes(map->lane(laneNode(*map, 4, 0)))));
  const auto two =
      planFleet(planner, {{"robot_1", start, 1.0}, {"robot_2", start, 1.0}}, {&uncertain, &other});
  ASSERT_TRUE(two[0].plan.ok() && two[1].plan.ok());
  EXPECT_NE(two[0].plan.ranked.front().target_picker, "");
  EXPECT_NE(two[1].plan.ranked.front().target_picker, "");
  EXPECT_NE(two[0].plan.ranked.front().target_picker, two[1].plan.ranked.front().target_picker);
}

TEST(NbsFleet, PriorityIsNaturalIdOrder) {
  EXPECT_TRUE(robotHasPriority("robot_1", "robot_2"));
  EXPECT_TRUE(robotHasPriority("robot_2", "robot_10"));
  EXPECT_FALSE(robotHasPriority("robot_10", "robot_2"));
  EXPECT_FALSE(robotHasPriority("robot_3", "robot_3"));
  const std::vector<Claim> all{{"robot_1", 4, "a"}, {"robot_3", 5, "b"}, {"robot_2", 6, ""}};
  const auto c = claimsFor("robot_2", all);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].robot_id, "robot_1");
  EXPECT_EQ(claimsFor("robot_1", all).size(), 0u);
  EXPECT_EQ(claimsFor("robot_3", all).size(), 2u);
}

TEST(EstimatedNodePolicy, GoesToTheMapNodeOrTheNearestUnclaimedOne) {
  auto map = wideTunnels();
  const NodeIndex estimate = laneNode(*map, 3, 4);
  NodeMasses m = uniformOver(*map, map->laneNodes(map->lane(estimate)));
  m[estimate] += 0.5;  // MAP node (normalised by the source)
  StaticBeliefSource picker("p", m);
  PlannerConfig cfg;
  cfg.policy = Policy::kEstimatedNode;
  const NextBestSensePlanner planner(map, cfg);
  const NodeIndex robot = *map->index("H0");
  const PlanResult r = planner.plan(robot, 1.0, {&picker});
  ASSERT_TRUE(r.ok()) << r.problem;
  EXPECT_EQ(r.ranked.front().node, estimate);
  EXPECT_DOUBLE_EQ(r.ranked.front().utility, 1.0);
  EXPECT_EQ(r.ranked.front().target_picker, "p");
  // Claimed by a robot with priority: a neighbour of the estimate (3 m away), the one nearer the robot.
  const PlanResult claimed = planner.plan(robot, 1.0, {&picker}, {{"robot_0", estimate, "p"}});
  ASSERT_TRUE(claimed.ok());
  EXPECT_NEAR(map->pathLength(claimed.ranked.front().node, estimate), 3.0, 1e-9);
  EXPECT_EQ(claimed.ranked.front().node, laneNode(*map, 3, 3));
  // No belief yet: a clear problem, no goal.
  StaticBeliefSource empty("e", NodeMasses(map->numNodes(), 0.0));
  const PlanResult none = planner.plan(robot, 1.0, {&empty});
  EXPECT_FALSE(none.ok());
  EXPECT_FALSE(none.problem.empty());
}

// Call-aware idle positioning: TrayClock's rule, hand-computed.
TEST(TrayClock, WeightGrowsWithTheTimeSinceTheTraysWereEmptied) {
  TrayClock clock(4.0, 300.0);
  // Never called: counted from the first time the clock is asked (the shift's start).
  EXPECT_DOUBLE_EQ(clock.weight("a", 1000.0), 1.0);
  EXPECT_DOUBLE_EQ(clock.weight("a", 1150.0), 1.0 + 4.0 * 0.5);
  EXPECT_DOUBLE_EQ(clock.weight("b", 1150.0), 3.0);    // any picker: the same start
  EXPECT_DOUBLE_EQ(clock.weight("a", 2000.0), 5.0);    // saturates at a whole tray time
  clock.observeCall("a", 1900.0, std::nan(""), true);  // calling, no robot there yet: full
  EXPECT_DOUBLE_EQ(clock.weight("a", 1901.0), 5.0);
  clock.observeCall("a", 1900.0, 1960.0, true);  // a robot reached it: emptied then
  EXPECT_DOUBLE_EQ(clock.weight("a", 1960.0), 1.0);
  EXPECT_DOUBLE_EQ(clock.weight("a", 2020.0), 1.0 + 4.0 * 0.2);
  clock.observeCall("a", 2100.0, std::nan(""), false);  // a later call cancelled before any robot came
  EXPECT_DOUBLE_EQ(clock.weight("a", 2110.0), 1.0 + 4.0 * 0.5);  // the trays as they were
  clock.observeCall("a", 1900.0, 1960.0, false);                 // the older call reported again: no change
  EXPECT_DOUBLE_EQ(clock.weight("a", 2110.0), 3.0);
  StaticBeliefSource a("a", {}), b("b", {});
  const PickerWeights w = clock.weights({&a, &b}, 2110.0);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_DOUBLE_EQ(w.at("b"), 5.0);
  clock.reset();  // the clock jumped back: start again
  EXPECT_DOUBLE_EQ(clock.weight("a", 10.0), 1.0);
  // Weight 0: every picker 1 (the planner as before).
  TrayClock off(0.0, 300.0);
  off.observeCall("a", 5.0, std::nan(""), true);
  EXPECT_DOUBLE_EQ(off.weight("a", 0.0), 1.0);
  EXPECT_DOUBLE_EQ(off.weight("a", 1e6), 1.0);
  EXPECT_THROW(TrayClock(-1.0, 300.0), std::invalid_argument);
  EXPECT_THROW(TrayClock(1.0, 0.0), std::invalid_argument);
}

TEST(NbsPlanner, PickerAboutToCallWeighsMore) {
  auto map = wideTunnels();
  // Two equally uncertain pickers in mirror lanes; the robot on the headland between them.
  StaticBeliefSource left("left", uniformOver(*map, map->laneNodes(map->lane(laneNode(*map, 0, 0)))));
  StaticBeliefSource right("right", uniformOver(*map, map->laneNodes(map->lane(laneNode(*map, 4, 0)))));
  const NodeIndex robot = *map->index("H2");
  NextBestSensePlanner planner(map, PlannerConfig{});
  const PlanResult even = planner.plan(robot, 1.0, {&left, &right});
  ASSERT_TRUE(even.ok()) << even.problem;
  for (int k = 0; k < 10; ++k) {  // mirror candidates tie without weights
    const Candidate* l = find(even, laneNode(*map, 0, k));
    const Candidate* r = find(even, laneNode(*map, 4, k));
    ASSERT_TRUE(l && r);
    EXPECT_NEAR(l->raw[kRfidGain], r->raw[kRfidGain], 1e-12) << "lane node " << k;
  }
  // The right picker's trays are nearly full: its gain counts 3x, so the best goal is in its lane.
  for (const auto& [due, other] : {std::pair<std::string, int>{"right", 4}, {"left", 0}}) {
    const PlanResult r = planner.plan(robot, 1.0, {&left, &right}, {}, {{due, 3.0}});
    ASSERT_TRUE(r.ok()) << r.problem;
    EXPECT_EQ(map->lane(r.ranked.front().node), map->lane(laneNode(*map, other, 0)))
        << map->node(r.ranked.front().node).name;
    EXPECT_EQ(r.ranked.front().target_picker, due);
    const Candidate* c = find(r, laneNode(*map, other, 3));
    const Candidate* base = find(even, laneNode(*map, other, 3));
    ASSERT_TRUE(c && base);
    EXPECT_NEAR(c->raw[kRfidGain], 3.0 * base->raw[kRfidGain], 1e-12);
  }
  // The keys, and a bad value refused.
  const PlannerConfig cfg =
      PlannerConfig::fromYaml(YAML::Load("{call_due_weight: 4.0, tray_time_mean: 300}"));
  EXPECT_DOUBLE_EQ(cfg.call_due_weight, 4.0);
  EXPECT_DOUBLE_EQ(cfg.tray_time_mean, 300.0);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("{call_due_weight: -1}")), std::runtime_error);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("{tray_time_mean: 0}")), std::runtime_error);
}
