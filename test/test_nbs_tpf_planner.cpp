// Next-Best-Sense with real Topological Particle Filters (the TPF what-if API): the planner sends the robot
// towards the picker whose belief is uncertain, and a plan is reproducible.
#include <gtest/gtest.h>

#include <memory>

#include "picker_localisation/nbs/next_best_sense_planner.h"
#include "picker_localisation/nbs/tpf_belief_source.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;
using namespace picker_localisation::nbs;
using topology::NodeIndex;

namespace {

std::shared_ptr<const topology::TopologicalMap> wideTunnels() {
  topology::PolytunnelSpec spec;
  spec.lanes = 5;
  spec.nodes_per_lane = 10;
  spec.lane_spacing = 8.0;
  spec.node_spacing = 2.0;  // a 3 m read region covers three lane nodes
  return std::make_shared<const topology::TopologicalMap>(topology::makePolytunnelMap(spec));
}

core::Observation gnss(const topology::TopologicalMap& map, const std::string& picker, double stamp,
                       const Eigen::Vector2d& mean, double sx, double sy) {
  core::Observation obs;
  obs.stamp = stamp;
  obs.sensor = "gnss";
  obs.picker_id = picker;
  obs.identifying = true;
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  cov(0, 0) = sx * sx;
  cov(1, 1) = sy * sy;
  core::setGaussianLikelihood(obs, map, mean, cov);
  return obs;
}

}  // namespace

TEST(NbsWithTpf, PrefersTheUncertainPicker) {
  auto map = wideTunnels();
  tpf::TopologicalParticleFilter confident(map, tpf::TpfParams(), 3), uncertain(map, tpf::TpfParams(), 4);
  const Eigen::Vector2d lane0_mid = map->position2d(*map->index("r0_5"));
  const Eigen::Vector2d lane4_mid = map->position2d(*map->index("r4_5"));
  // Confident: ten tight fixes on one node saying the picker stands still (GNSS velocity 0, gamma_v = 1), so
  // its belief stays put when predicted to the robot's arrival. Uncertain: one fix spread along the lane (sigma 5 m).
  for (int k = 0; k < 10; ++k) {
    core::Observation fix = gnss(*map, "confident", k, lane0_mid, 0.3, 0.3);
    fix.velocity = Eigen::Vector2d::Zero();
    ASSERT_TRUE(confident.update(fix).ok());
  }
  ASSERT_TRUE(uncertain.update(gnss(*map, "uncertain", 9.0, lane4_mid, 0.5, 5.0)).ok());
  ASSERT_LT(confident.belief().entropy, 0.7);
  ASSERT_GT(uncertain.belief().entropy, 1.2);

  TpfBeliefSource a("confident", confident, 7), b("uncertain", uncertain, 7);
  const NodeIndex robot = *map->index("H2");  // equally far from lanes 0 and 4
  const NextBestSensePlanner planner(map, PlannerConfig{});
  const PlanResult r = planner.plan(robot, 0.9, {&a, &b});
  ASSERT_TRUE(r.ok()) << r.problem;
  EXPECT_GT(r.what_if_queries, 0u);
  const Candidate& best = r.ranked.front();
  EXPECT_EQ(map->lane(best.node), map->lane(*map->index("r4_0"))) << map->node(best.node).name;
  EXPECT_EQ(best.target_picker, "uncertain");
  // The best node of lane 4 beats the best node of lane 0 on the RFID gain and on utility.
  double gain0 = 0, gain4 = 0, util0 = 0, util4 = 0;
  for (const Candidate& c : r.ranked) {
    if (map->lane(c.node) == map->lane(*map->index("r0_0"))) {
      gain0 = std::max(gain0, c.raw[kRfidGain]);
      util0 = std::max(util0, c.utility);
    }
    if (map->lane(c.node) == map->lane(*map->index("r4_0"))) {
      gain4 = std::max(gain4, c.raw[kRfidGain]);
      util4 = std::max(util4, c.utility);
    }
  }
  EXPECT_GT(gain4, gain0);
  EXPECT_GT(util4, util0);
  // The live filters are untouched and the plan is reproducible.
  EXPECT_EQ(uncertain.belief().observations, 1u);
  const PlanResult again = planner.plan(robot, 0.9, {&a, &b});
  ASSERT_EQ(again.ranked.size(), r.ranked.size());
  for (std::size_t i = 0; i < r.ranked.size(); ++i) {
    EXPECT_EQ(again.ranked[i].node, r.ranked[i].node);
    EXPECT_DOUBLE_EQ(again.ranked[i].utility, r.ranked[i].utility);
  }
}

TEST(NbsWithTpf, UninitialisedFilterGivesNoGainAndNoEstimate) {
  auto map = wideTunnels();
  tpf::TopologicalParticleFilter empty(map, tpf::TpfParams(), 1);
  TpfBeliefSource s("p", empty);
  EXPECT_EQ(s.estimatedNode(), topology::kInvalidNode);
  EXPECT_TRUE(s.predicted(1.0).empty());
  PlannerConfig cfg;
  const PlanResult r = NextBestSensePlanner(map, cfg).plan(*map->index("H0"), 1.0, {&s});
  ASSERT_TRUE(r.ok());  // still ranks by distance / time / battery
  for (const Candidate& c : r.ranked) EXPECT_DOUBLE_EQ(c.raw[kRfidGain], 0.0);
  EXPECT_EQ(r.ranked.front().node, *map->index("H0"));  // nothing to gain anywhere: stay
  cfg.policy = Policy::kEstimatedNode;
  EXPECT_FALSE(NextBestSensePlanner(map, cfg).plan(*map->index("H0"), 1.0, {&s}).ok());
}
