// Next-Best-Sense with real Topological Particle Filters (the TPF what-if API): the planner sends the robot
// towards the picker whose belief is uncertain, and a plan is reproducible.
#include <gtest/gtest.h>

#include <memory>

#include "nbs_test_maps.h"
#include "picker_localisation/nbs/next_best_sense_planner.h"
#include "picker_localisation/nbs/tpf_belief_source.h"

using namespace picker_localisation;
using namespace picker_localisation::nbs;
using nbs_test::wideTunnels;
using topology::NodeIndex;

namespace {

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
  auto map = wideTunnels(2.0);  // a 3 m read region covers three lane nodes
  tpf::TopologicalParticleFilter confident(map, tpf::TpfParams(), 3), uncertain(map, tpf::TpfParams(), 4);
  const Eigen::Vector2d lane0_mid = map->position2d(*map->index("r0_5"));
  const Eigen::Vector2d lane4_mid = map->position2d(*map->index("r4_5"));
  // Confident: ten tight fixes on one node saying the picker stands still (GNSS velocity 0, gamma_v = 1), so
  // its belief stays put when predicted to the robot's arrival. Uncertain: one fix spread along the lane
  // (sigma 5 m).
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
  // A fast robot (arrival within ~2 s): the comparison is about the beliefs' shapes, not about how far the
  // filter's motion model spreads them while the robot drives (that part is the TPF's, tested there).
  PlannerConfig cfg;
  cfg.energy.speed = 20.0;
  const NextBestSensePlanner planner(map, cfg);
  const PlanResult r = planner.plan(robot, 0.9, {&a, &b});
  ASSERT_TRUE(r.ok()) << r.problem;
  EXPECT_GT(r.what_if_queries, 0u);
  // Candidates at the pickers' estimated nodes (mirror nodes, same travel distance): sensing by the
  // confident picker teaches almost nothing (its predicted belief lies inside the read region whatever the
  // outcome), sensing by the uncertain one splits its belief.
  const NodeIndex at_confident = confident.belief().map_node, at_uncertain = uncertain.belief().map_node;
  ASSERT_EQ(at_confident, *map->index("r0_5"));
  ASSERT_EQ(at_uncertain, *map->index("r4_5"));
  const Candidate *c0 = nullptr, *c4 = nullptr;
  for (const Candidate& c : r.ranked) {
    if (c.node == at_confident) c0 = &c;
    if (c.node == at_uncertain) c4 = &c;
  }
  ASSERT_TRUE(c0 && c4);
  ASSERT_NEAR(c0->raw[kTravelDistance], c4->raw[kTravelDistance], 1e-9);
  EXPECT_GT(c4->raw[kRfidGain], 0.2);
  EXPECT_GT(c4->raw[kRfidGain], 5.0 * c0->raw[kRfidGain]);
  EXPECT_GT(c4->utility, c0->utility + 0.1);
  EXPECT_EQ(c4->target_picker, "uncertain");
  // Over whole lanes, the uncertain picker's lane offers more: the summed gain of its nodes is larger.
  double sum0 = 0.0, sum4 = 0.0;
  for (const Candidate& c : r.ranked) {
    if (map->lane(c.node) == map->lane(at_confident)) sum0 += c.raw[kRfidGain];
    if (map->lane(c.node) == map->lane(at_uncertain)) sum4 += c.raw[kRfidGain];
  }
  EXPECT_GT(sum4, sum0);
  // And the planner's goal serves the uncertain picker, in its lane.
  EXPECT_EQ(r.ranked.front().target_picker, "uncertain");
  EXPECT_EQ(map->lane(r.ranked.front().node), map->lane(at_uncertain)) << map->node(r.ranked.front().node).name;
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

TEST(NbsWithTpf, BeliefSourceAnswersAsTheFilterAtEveryHorizonAndAfterUpdates) {
  // The source predicts once per horizon and answers every hypothesis at that horizon from that prediction;
  // its answers must be the filter's own what-if answers (same seed), and follow the live filter when it
  // changes.
  auto map = wideTunnels(2.0);
  tpf::TopologicalParticleFilter f(map, tpf::TpfParams(), 5);
  const Eigen::Vector2d mid = map->position2d(*map->index("r2_5"));
  ASSERT_TRUE(f.update(gnss(*map, "p", 1.0, mid, 0.5, 4.0)).ok());
  TpfBeliefSource s("p", f, 11);
  core::Observation read;
  read.sensor = "rfid";
  read.picker_id = "p";
  read.identifying = true;
  read.nodes = {*map->index("r2_5"), *map->index("r2_6")};
  read.likelihood = {1.0, 1.0};
  const auto dense = [&](const tpf::Belief& b) { return denseMasses(b, map->numNodes()); };
  for (int round = 0; round < 2; ++round) {
    for (double h : {0.0, 4.0, 10.0, 4.0}) {
      EXPECT_EQ(s.predicted(h), dense(f.predictAhead(h, 11))) << "horizon " << h;
      EXPECT_EQ(s.posterior(h, read), dense(f.posteriorUnder(read, h, 11))) << "horizon " << h;
    }
    const NodeMasses before = s.posterior(4.0, read);
    ASSERT_TRUE(f.update(gnss(*map, "p", 5.0, map->position2d(*map->index("r2_8")), 0.5, 0.5)).ok());
    EXPECT_NE(s.posterior(4.0, read), before);  // the live filter moved: no stale answer
  }
}
