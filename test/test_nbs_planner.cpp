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

// The same-lane LiDAR view (lidar/view_range): a stop 9 m up the picker's lane (outside the 3 m read disc)
// gains nothing with RFID alone and gains with the view; a stop in the next lane gains nothing either way.
TEST(NbsPlanner, LidarViewAlongTheLaneCountsInTheGain) {
  auto map = wideTunnels();
  const NodeIndex a = laneNode(*map, 0, 2), b = laneNode(*map, 0, 5), c = laneNode(*map, 0, 8);
  StaticBeliefSource picker("p", uniformOver(*map, {a, b}));
  PlannerConfig rfid_only;
  const PlanResult r0 = NextBestSensePlanner(map, rfid_only).plan(c, 1.0, {&picker});
  PlannerConfig with_view;
  with_view.lidar.view_range = 10.0;
  with_view.lidar.p_detect = 0.6;
  const PlanResult r1 = NextBestSensePlanner(map, with_view).plan(c, 1.0, {&picker});
  ASSERT_TRUE(r0.ok() && r1.ok());
  EXPECT_DOUBLE_EQ(find(r0, c)->raw[kRfidGain], 0.0);
  // From c, b (9 m) is in view, a (18 m) is not: seen -> certain, unseen -> (0.5, 0.5 (1 - p)) normalised.
  const double p = 0.6;
  const double q_a = 1 / (2 - p), q_b = (1 - p) / (2 - p);
  const double expected = std::log(2.0) - (1 - 0.5 * p) * (-q_a * std::log(q_a) - q_b * std::log(q_b));
  EXPECT_NEAR(find(r1, c)->raw[kRfidGain], expected, 1e-12);
  EXPECT_DOUBLE_EQ(find(r1, laneNode(*map, 1, 5))->raw[kRfidGain], 0.0);  // beds hide the next lane
  with_view.lidar.view_range = -1.0;
  EXPECT_NE(with_view.validate(), "");
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

// The lane check (issue "Find the lane"): a picker whose belief sits confidently on one node has no entropy
// to lose, but when its GNSS bias is uncertain the truth may be a lane or two off. The gain of a stop is
// p_detect * P(in view of the stop, belief blurred by the bias covariance) * lane entropy of the blurred
// belief. Expected values computed here from the definition in the header, node by node.
TEST(NbsPlanner, LaneCheckValuesASightingOfAPickerWithAnUncertainBias) {
  auto map = wideTunnels();
  const NodeIndex a = laneNode(*map, 2, 5);
  StaticBeliefSource picker("p", uniformOver(*map, {a}));
  Eigen::Matrix2d cov;
  cov << 25.0, 3.0, 3.0, 16.0;  // m^2, spreads the truth over lanes 1-3 (8 m apart)
  picker.setBiasCovariance(cov);
  PlannerConfig cfg;
  EXPECT_EQ(cfg.lane_check.weight, 0.0);  // off by default (measured, docs/readme/nbs.md "Lane check")
  cfg.lane_check.weight = 1.0;
  const PlanResult r = NextBestSensePlanner(map, cfg).plan(a, 1.0, {&picker});
  ASSERT_TRUE(r.ok()) << r.problem;

  // The belief blurred by a covariance, by the definition: Gaussian weights (covariance + 0.01 I) over the
  // nodes within 3 sigma of a, normalised; and the entropy of its lane masses.
  auto blurred = [&](const Eigen::Matrix2d& c) {
    const Eigen::Matrix2d s = c + 0.01 * Eigen::Matrix2d::Identity();
    const double largest = 0.5 * (c(0, 0) + c(1, 1)) +
                           std::sqrt(0.25 * (c(0, 0) - c(1, 1)) * (c(0, 0) - c(1, 1)) + c(0, 1) * c(0, 1));
    const double radius = 3.0 * std::sqrt(largest + 0.01);
    std::vector<double> t(map->numNodes(), 0.0);
    double z = 0.0;
    for (std::size_t m = 0; m < map->numNodes(); ++m) {
      const Eigen::Vector2d d = map->position2d(static_cast<NodeIndex>(m)) - map->position2d(a);
      if (d.norm() > radius) continue;
      t[m] = std::exp(-0.5 * d.dot(s.inverse() * d));
      z += t[m];
    }
    for (double& v : t) v /= z;
    return t;
  };
  auto laneMasses = [&](const std::vector<double>& t) {
    std::vector<double> lanes(map->numLanes() + 1, 0.0);
    for (std::size_t m = 0; m < t.size(); ++m) {
      const auto l = map->lane(static_cast<NodeIndex>(m));
      lanes[l == topology::kNoLane ? map->numLanes() : static_cast<std::size_t>(l)] += t[m];
    }
    return lanes;
  };
  auto laneEntropy = [&](const std::vector<double>& t) {
    double h = 0.0;
    for (double p : laneMasses(t))
      if (p > 0.0) h -= p * std::log(p);
    return h;
  };
  const std::vector<double> t = blurred(cov);
  // After a sighting (R = 0.5^2 I): S' = (S^-1 + R^-1)^-1.
  const Eigen::Matrix2d after =
      (cov.inverse() + Eigen::Matrix2d::Identity() / std::pow(cfg.lane_check.sighting_std, 2)).inverse();
  const double h_before = laneEntropy(t), h_after = laneEntropy(blurred(after));
  EXPECT_GT(h_before, 0.5);          // the truth is spread over several lanes
  EXPECT_LT(h_after, 0.01);          // a sighting names the lane (0.5 m against lanes 8 m apart)
  EXPECT_GT(laneMasses(t)[2], 0.5);  // most of it still in the belief's lane
  auto gainAt = [&](NodeIndex c) {
    double in_view = 0.0;
    for (std::size_t m = 0; m < t.size(); ++m)
      if (map->lane(static_cast<NodeIndex>(m)) == map->lane(c) &&
          map->distance(static_cast<NodeIndex>(m), c) <= cfg.lane_check.view_range + 1e-9)
        in_view += t[m];
    return cfg.lane_check.p_detect * in_view * (h_before - h_after);
  };
  // The belief is certain: no RFID gain, so rfid_gain is the lane gain alone.
  for (NodeIndex c : {a, laneNode(*map, 1, 5), laneNode(*map, 3, 2), laneNode(*map, 0, 5)}) {
    const Candidate* cand = find(r, c);
    ASSERT_NE(cand, nullptr);
    EXPECT_NEAR(cand->raw[kRfidGain], gainAt(c), 1e-9) << map->node(c).name;
  }
  EXPECT_GT(find(r, laneNode(*map, 1, 5))->raw[kRfidGain], 0.0);  // a neighbouring lane may be the true one
  EXPECT_DOUBLE_EQ(find(r, *map->index("H2"))->raw[kRfidGain], 0.0);  // a headland node sees no lane
  EXPECT_EQ(r.ranked.front().target_picker, "p");

  // A fresh bias (1 cm) or lane_check off: a certain belief gives nothing anywhere.
  picker.setBiasCovariance(1e-5 * Eigen::Matrix2d::Identity());
  for (const Candidate& c : NextBestSensePlanner(map, cfg).plan(a, 1.0, {&picker}).ranked)
    EXPECT_DOUBLE_EQ(c.raw[kRfidGain], 0.0) << map->node(c.node).name;
  picker.setBiasCovariance(cov);
  cfg.lane_check.weight = 0.0;
  for (const Candidate& c : NextBestSensePlanner(map, cfg).plan(a, 1.0, {&picker}).ranked)
    EXPECT_DOUBLE_EQ(c.raw[kRfidGain], 0.0) << map->node(c.node).name;
}

// Two pickers, both believed on one node, mirrored about the robot: the one whose bias is old is the one to
// see.
TEST(NbsPlanner, LaneCheckSendsTheRobotToThePickerWithTheOldBias) {
  auto map = wideTunnels();
  StaticBeliefSource fresh("fresh", uniformOver(*map, {laneNode(*map, 0, 5)}));
  StaticBeliefSource old("old", uniformOver(*map, {laneNode(*map, 4, 5)}));
  fresh.setBiasCovariance(0.04 * Eigen::Matrix2d::Identity());  // sighted a moment ago
  old.setBiasCovariance(16.0 * Eigen::Matrix2d::Identity());    // never sighted
  const NodeIndex robot = *map->index("H2");
  PlannerConfig cfg;
  cfg.lane_check.weight = 1.0;
  const PlanResult r = NextBestSensePlanner(map, cfg).plan(robot, 1.0, {&fresh, &old});
  ASSERT_TRUE(r.ok()) << r.problem;
  EXPECT_EQ(r.ranked.front().target_picker, "old");
  EXPECT_LE(std::abs(map->lane(r.ranked.front().node) - map->lane(laneNode(*map, 4, 0))), 1)
      << map->node(r.ranked.front().node).name;
  // Swap the ages: the goal follows.
  fresh.setBiasCovariance(16.0 * Eigen::Matrix2d::Identity());
  old.setBiasCovariance(0.04 * Eigen::Matrix2d::Identity());
  const PlanResult swapped = NextBestSensePlanner(map, cfg).plan(robot, 1.0, {&fresh, &old});
  ASSERT_TRUE(swapped.ok());
  EXPECT_EQ(swapped.ranked.front().target_picker, "fresh");
}

TEST(NbsPlanner, LaneCheckOptionsFromYaml) {
  std::vector<std::string> unknown;
  const PlannerConfig c = PlannerConfig::fromYaml(
      YAML::Load("lane_check: {weight: 0.5, view_range: 6.0, p_detect: 0.4, sighting_std: 0.3, range: 3}"),
      &unknown);
  EXPECT_DOUBLE_EQ(c.lane_check.weight, 0.5);
  EXPECT_DOUBLE_EQ(c.lane_check.view_range, 6.0);
  EXPECT_DOUBLE_EQ(c.lane_check.p_detect, 0.4);
  EXPECT_DOUBLE_EQ(c.lane_check.sighting_std, 0.3);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_NE(unknown[0].find("range"), std::string::npos);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("lane_check: {weight: -1}")), std::runtime_error);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("lane_check: {view_range: 0}")), std::runtime_error);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("lane_check: {p_detect: 1.5}")), std::runtime_error);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("lane_check: {sighting_std: 0}")), std::runtime_error);
}
