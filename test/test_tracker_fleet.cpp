// tpf::TrackerFleet, the tracker fleet tpf_tracker and the offline runner share: routing by identity and
// candidates, the prediction schedule (lastStamp + k / prediction_rate, before an observation and while none
// arrives), the belief listener, remove / reset / adoptMap.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/topology/synthetic_map.h"
#include "picker_localisation/tpf/tracker_fleet.h"

using namespace picker_localisation;
using topology::NodeIndex;
using tpf::TrackerFleet;

namespace {

std::shared_ptr<const topology::TopologicalMap> polytunnel() {
  return std::make_shared<const topology::TopologicalMap>(
      topology::makePolytunnelMap(topology::PolytunnelSpec()));
}

core::Observation seenAt(double stamp, NodeIndex node, const std::string& picker) {
  core::Observation o;
  o.stamp = stamp;
  o.sensor = "gnss";
  o.identifying = !picker.empty();
  o.picker_id = picker;
  o.nodes = {node};
  o.likelihood = {1.0};
  return o;
}

// Records every belief change the fleet reports: (picker, stamp).
struct Recorder {
  std::vector<std::pair<std::string, double>> changes;
  TrackerFleet::BeliefListener listener() {
    return [this](TrackerFleet::Track& t) { changes.emplace_back(t.id, t.filter->belief().stamp); };
  }
  std::vector<double> stampsOf(const std::string& id) const {
    std::vector<double> s;
    for (const auto& c : changes)
      if (c.first == id) s.push_back(c.second);
    return s;
  }
};

tpf::TpfParams params(double prediction_rate = 0.25) {
  tpf::TpfParams p;
  p.num_particles = 200;
  p.prediction_rate = prediction_rate;
  return p;
}

}  // namespace

TEST(TrackerFleet, RoutesByIdentityCandidatesOrToEveryone) {
  auto map = polytunnel();
  TrackerFleet fleet(map);
  for (const char* id : {"a", "b", "c"}) ASSERT_NE(fleet.add(id, params(), 7), nullptr);
  // Identified: that picker only; an unknown one: nobody.
  auto outcomes = fleet.process(seenAt(1.0, 3, "b"));
  ASSERT_EQ(outcomes.size(), 1u);
  EXPECT_EQ(outcomes[0].track->id, "b");
  EXPECT_TRUE(fleet.process(seenAt(1.0, 3, "nobody")).empty());
  // Anonymous with candidates: those tracked among them.
  core::Observation person = seenAt(2.0, 4, "");
  person.candidate_pickers = {"a", "c", "unknown"};
  outcomes = fleet.process(person);
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_EQ(outcomes[0].track->id, "a");
  EXPECT_EQ(outcomes[1].track->id, "c");
  // Anonymous, no candidates: everyone.
  EXPECT_EQ(fleet.process(seenAt(3.0, 4, "")).size(), 3u);
  EXPECT_EQ(fleet.find("b")->received, 2u);
}

TEST(TrackerFleet, GivesEachCandidateItsAssociationProbability) {
  // Two trackers whose beliefs sit half at node 3 and half at node 40; a person at node 40 that is "a" with
  // probability 0.9 and "c" with 0.1 (gnss_ingest's candidate_probabilities). Each tracker weighs it by its
  // own probability, so a's belief moves to node 40 far more than c's.
  auto map = polytunnel();
  TrackerFleet fleet(map);
  for (const char* id : {"a", "c"}) ASSERT_NE(fleet.add(id, params(0.0), 7), nullptr);
  core::Observation split = seenAt(1.0, 3, "");
  split.nodes = {3, 40};
  split.likelihood = {1.0, 1.0};
  fleet.process(split);
  core::Observation person = seenAt(2.0, 40, "");
  person.sensor = "lidar";
  person.candidate_pickers = {"a", "c"};
  person.candidate_probabilities = {0.9, 0.1};
  EXPECT_DOUBLE_EQ(core::associationProbability(person, "a"), 0.9);
  EXPECT_DOUBLE_EQ(core::associationProbability(person, "c"), 0.1);
  EXPECT_DOUBLE_EQ(core::associationProbability(person, "b"), 0.0);
  ASSERT_EQ(fleet.process(person).size(), 2u);
  const double a = fleet.find("a")->filter->belief().massOf(40),
               c = fleet.find("c")->filter->belief().massOf(40);
  EXPECT_GT(a, 0.85);
  EXPECT_LT(c, 0.75);
  EXPECT_GT(a - c, 0.25);
  // Probabilities that do not match the candidates are a malformed observation: refused, the belief kept.
  person.stamp = 3.0;
  person.candidate_probabilities = {0.9};
  const auto outcomes = fleet.process(person);
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_EQ(outcomes[0].result.status, tpf::UpdateStatus::kRejectedInvalid);
  EXPECT_NE(outcomes[0].result.reason.find("candidate_probabilities"), std::string::npos);
  person.candidate_probabilities = {0.9, std::nan("")};
  EXPECT_EQ(fleet.process(person)[0].result.status, tpf::UpdateStatus::kRejectedInvalid);
  // Without probabilities every candidate takes the person as its picker (and an identified one too).
  person.candidate_probabilities.clear();
  EXPECT_DOUBLE_EQ(core::associationProbability(person, "c"), 1.0);
  EXPECT_DOUBLE_EQ(core::associationProbability(seenAt(1.0, 3, "b"), "b"), 1.0);
}

TEST(TrackerFleet, PredictsOnTheScheduleWhateverWhenItIsAsked) {
  // Two fleets with the same seed: one asked for predictions every 0.1 s, the other once at the end. Both
  // predict at lastStamp + 4 k (0.25 Hz), so both hold the same belief at the same stamp.
  auto map = polytunnel();
  Recorder often, once;
  TrackerFleet a(map, often.listener()), b(map, once.listener());
  a.add("p", params(), 11);
  b.add("p", params(), 11);
  a.process(seenAt(10.0, 5, "p"));
  b.process(seenAt(10.0, 5, "p"));
  for (double t = 10.1; t < 23.05; t += 0.1) a.predictDue(t);
  b.predictDue(23.0);
  EXPECT_EQ(often.stampsOf("p"), (std::vector<double>{10.0, 14.0, 18.0, 22.0}));
  EXPECT_EQ(once.stampsOf("p"), often.stampsOf("p"));
  EXPECT_EQ(a.find("p")->filter->belief().masses, b.find("p")->filter->belief().masses);
  // An observation at 31 s: the predictions due before it (26, 30) come first, then the update.
  a.process(seenAt(31.0, 6, "p"));
  EXPECT_EQ(often.stampsOf("p"), (std::vector<double>{10.0, 14.0, 18.0, 22.0, 26.0, 30.0, 31.0}));
}

TEST(TrackerFleet, NoPeriodicPredictionAtRateZeroAndFastestPeriod) {
  auto map = polytunnel();
  Recorder rec;
  TrackerFleet fleet(map, rec.listener());
  EXPECT_EQ(fleet.fastestPredictionPeriod(), 0.0);
  fleet.add("still", params(0.0), 1);
  fleet.process(seenAt(1.0, 2, "still"));
  fleet.predictDue(100.0);
  EXPECT_EQ(rec.stampsOf("still"), (std::vector<double>{1.0}));
  EXPECT_EQ(fleet.fastestPredictionPeriod(), 0.0);
  fleet.add("fast", params(2.0), 2);
  fleet.add("slow", params(0.5), 3);
  EXPECT_DOUBLE_EQ(fleet.fastestPredictionPeriod(), 0.5);
}

TEST(TrackerFleet, RefusedObservationsAreNotBeliefChanges) {
  auto map = polytunnel();
  Recorder rec;
  TrackerFleet fleet(map, rec.listener());
  fleet.add("p", params(), 1);
  core::Observation bad = seenAt(1.0, 2, "p");
  bad.likelihood = {std::nan("")};
  const auto outcomes = fleet.process(bad);
  ASSERT_EQ(outcomes.size(), 1u);
  EXPECT_FALSE(outcomes[0].result.ok());
  EXPECT_FALSE(outcomes[0].exception);
  EXPECT_TRUE(rec.changes.empty());
  EXPECT_NE(fleet.find("p")->last_problem, "");
}

TEST(TrackerFleet, AddRemoveResetAndAdoptMap) {
  auto map = polytunnel();
  Recorder rec;
  TrackerFleet fleet(map, rec.listener());
  ASSERT_NE(fleet.add("p", params(), 1), nullptr);
  std::string error;
  EXPECT_EQ(fleet.add("p", params(), 1, &error), nullptr);
  EXPECT_NE(error.find("tracked already"), std::string::npos);
  tpf::TpfParams bad = params();
  bad.num_particles = 0;
  EXPECT_EQ(fleet.add("q", bad, 1, &error), nullptr);
  EXPECT_EQ(fleet.size(), 1u);
  fleet.process(seenAt(1.0, 2, "p"));
  ASSERT_TRUE(fleet.find("p")->filter->initialised());
  fleet.resetAll();
  EXPECT_FALSE(fleet.find("p")->filter->initialised());
  EXPECT_EQ(fleet.find("p")->resets, 1u);
  EXPECT_EQ(rec.changes.size(), 2u);  // the update and the reset
  // The same map again, node for node: the belief is carried over and reported.
  fleet.process(seenAt(2.0, 7, "p"));
  std::vector<NodeIndex> same(map->numNodes());
  for (NodeIndex n = 0; n < same.size(); ++n) same[n] = n;
  const auto copy = std::make_shared<const topology::TopologicalMap>(*map);
  EXPECT_TRUE(fleet.adoptMap(copy, same).empty());
  EXPECT_EQ(fleet.map(), copy);
  EXPECT_EQ(fleet.find("p")->filter->belief().map_node, 7u);
  EXPECT_EQ(rec.changes.size(), 4u);
  EXPECT_TRUE(fleet.remove("p"));
  EXPECT_FALSE(fleet.remove("p"));
  EXPECT_TRUE(fleet.process(seenAt(3.0, 2, "p")).empty());
}
