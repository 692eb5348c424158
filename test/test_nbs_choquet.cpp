// The discrete Choquet integral of Navigate-and-Seek Eq. 13 and the fuzzy measure built from Table I.
#include <gtest/gtest.h>

#include <random>

#include "picker_localisation/nbs/choquet.h"
#include "picker_localisation/nbs/next_best_sense_planner.h"

using namespace picker_localisation::nbs;

namespace {
// Subsets as masks: criterion 0 = bit 1, 1 = bit 2, 2 = bit 4.
FuzzyMeasure handMeasure() {
  //                 {}   {a}  {b}  {ab} {c}  {ac} {bc} {abc}
  return FuzzyMeasure::fromSubsetValues({0.0, 0.2, 0.3, 0.6, 0.4, 0.5, 0.8, 1.0});
}
}  // namespace

TEST(Choquet, HandComputedThreeCriteria) {
  // u = (a 0.5, b 0.2, c 0.9): sorted b < a < c.
  // f = 0.2 mu({a,b,c}) + (0.5 - 0.2) mu({a,c}) + (0.9 - 0.5) mu({c}) = 0.2 + 0.3 * 0.5 + 0.4 * 0.4 = 0.51
  EXPECT_NEAR(choquetIntegral({0.5, 0.2, 0.9}, handMeasure()), 0.51, 1e-12);
  // u = (0.7, 0.7, 0.1): f = 0.1 * 1 + 0.6 * mu({a,b}) = 0.1 + 0.36 = 0.46
  EXPECT_NEAR(choquetIntegral({0.7, 0.7, 0.1}, handMeasure()), 0.46, 1e-12);
  // Only b is satisfied: f = mu({b}) = 0.3; all equal: f = u.
  EXPECT_NEAR(choquetIntegral({0.0, 1.0, 0.0}, handMeasure()), 0.3, 1e-12);
  EXPECT_NEAR(choquetIntegral({0.4, 0.4, 0.4}, handMeasure()), 0.4, 1e-12);
}

TEST(Choquet, AdditiveMeasureIsWeightedSum) {
  const std::vector<double> w{0.3, 0.1, 0.35, 0.25};  // Table I
  const FuzzyMeasure mu = FuzzyMeasure::fromWeights(w);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int trial = 0; trial < 1000; ++trial) {
    std::vector<double> u(4);
    double sum = 0.0;
    for (std::size_t i = 0; i < 4; ++i) {
      u[i] = u01(rng);
      sum += w[i] * u[i];
    }
    ASSERT_NEAR(choquetIntegral(u, mu), sum, 1e-12);
  }
  // Unnormalised weights are scaled to sum to 1.
  EXPECT_NEAR(choquetIntegral({1.0, 0.0}, FuzzyMeasure::fromWeights({3.0, 1.0})), 0.75, 1e-12);
}

TEST(Choquet, MonotoneInEachCriterion) {
  std::vector<FuzzyMeasure> measures{
      handMeasure(), PlannerConfig().measure(),
      FuzzyMeasure::fromWeights({0.3, 0.1, 0.35, 0.25}, {{0, 3, -0.4}, {1, 2, 0.5}})};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (const FuzzyMeasure& mu : measures) {
    const std::size_t n = mu.numCriteria();
    for (int trial = 0; trial < 2000; ++trial) {
      std::vector<double> u(n);
      for (double& x : u) x = u01(rng);
      const double f = choquetIntegral(u, mu);
      const double lo = *std::min_element(u.begin(), u.end()), hi = *std::max_element(u.begin(), u.end());
      ASSERT_GE(f, lo - 1e-12);
      ASSERT_LE(f, hi + 1e-12);
      for (std::size_t i = 0; i < n; ++i) {
        std::vector<double> v = u;
        v[i] = u[i] + (1.0 - u[i]) * u01(rng);  // raise criterion i only
        ASSERT_GE(choquetIntegral(v, mu), f - 1e-12) << "criterion " << i;
      }
    }
  }
}

TEST(FuzzyMeasureFromWeights, TableIDefaultsAreAMonotoneMeasure) {
  const FuzzyMeasure mu = PlannerConfig().measure();
  ASSERT_EQ(mu.numCriteria(), 4u);
  EXPECT_EQ(FuzzyMeasure::checkMeasure(mu.values()), "");
  const std::uint32_t td = 1u << kTravelDistance, st = 1u << kSensingTime, rf = 1u << kRfidGain,
                      bs = 1u << kBattery;
  EXPECT_DOUBLE_EQ(mu(0), 0.0);
  EXPECT_NEAR(mu(td | st | rf | bs), 1.0, 1e-12);
  EXPECT_NEAR(mu(td), 0.3, 1e-12);
  EXPECT_NEAR(mu(st), 0.1, 1e-12);
  EXPECT_NEAR(mu(rf), 0.35, 1e-12);
  EXPECT_NEAR(mu(bs), 0.25, 1e-12);
  EXPECT_NEAR(mu(rf | td), 0.3 + 0.35 + 0.1, 1e-12);  // synergy
  EXPECT_NEAR(mu(td | bs), 0.3 + 0.25 - 0.1, 1e-12);  // redundancy
  EXPECT_NEAR(mu(st | bs), 0.35, 1e-12);              // additive pair
}

TEST(FuzzyMeasureFromWeights, ClampAndClosureKeepItMonotone) {
  // A strong redundancy would make {0,1} worth less than {0}: the closure lifts it to mu({0}).
  const FuzzyMeasure red = FuzzyMeasure::fromWeights({0.5, 0.3, 0.2}, {{0, 1, -0.6}});
  EXPECT_EQ(FuzzyMeasure::checkMeasure(red.values()), "");
  EXPECT_NEAR(red(0b011), 0.5, 1e-12);
  EXPECT_NEAR(red(0b111), 1.0, 1e-12);
  // A strong synergy saturates at 1 before the full set.
  const FuzzyMeasure syn = FuzzyMeasure::fromWeights({0.5, 0.3, 0.2}, {{0, 1, 0.5}});
  EXPECT_EQ(FuzzyMeasure::checkMeasure(syn.values()), "");
  EXPECT_NEAR(syn(0b011), 1.0, 1e-12);
}

TEST(FuzzyMeasureFromWeights, RejectsBadInput) {
  EXPECT_THROW(FuzzyMeasure::fromWeights({}), std::invalid_argument);
  EXPECT_THROW(FuzzyMeasure::fromWeights({0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(FuzzyMeasure::fromWeights({0.5, -0.1}), std::invalid_argument);
  EXPECT_THROW(FuzzyMeasure::fromWeights({0.5, std::nan("")}), std::invalid_argument);
  EXPECT_THROW(FuzzyMeasure::fromWeights({0.5, 0.5}, {{0, 0, 0.1}}), std::invalid_argument);
  EXPECT_THROW(FuzzyMeasure::fromWeights({0.5, 0.5}, {{0, 2, 0.1}}), std::invalid_argument);
  EXPECT_THROW(FuzzyMeasure::fromSubsetValues({0.0, 0.6, 0.5}), std::invalid_argument);  // not 2^n
  EXPECT_THROW(FuzzyMeasure::fromSubsetValues({0.0, 0.6, 0.5, 0.4}),
               std::invalid_argument);  // not monotone, mu(all) != 1
  EXPECT_THROW(FuzzyMeasure::fromSubsetValues({0.0, 0.6, 0.7, 0.5}), std::invalid_argument);  // mu(all) != 1
  EXPECT_THROW(FuzzyMeasure::fromSubsetValues({0.1, 0.6, 0.7, 1.0}),
               std::invalid_argument);  // mu(empty) != 0
  EXPECT_THROW(choquetIntegral({0.5, 0.5}, handMeasure()), std::invalid_argument);
}

TEST(MinMaxNormalise, BenefitCostFlatAndNonFinite) {
  const std::vector<double> raw{2.0, 4.0, 3.0};
  const auto b = minMaxNormalise(raw, true), c = minMaxNormalise(raw, false);
  EXPECT_DOUBLE_EQ(b[0], 0.0);
  EXPECT_DOUBLE_EQ(b[1], 1.0);
  EXPECT_DOUBLE_EQ(b[2], 0.5);
  EXPECT_DOUBLE_EQ(c[0], 1.0);
  EXPECT_DOUBLE_EQ(c[1], 0.0);
  EXPECT_DOUBLE_EQ(c[2], 0.5);
  for (double v : minMaxNormalise({5.0, 5.0}, true)) EXPECT_DOUBLE_EQ(v, 1.0);
  const auto nf = minMaxNormalise({1.0, std::nan(""), 3.0}, true);
  EXPECT_DOUBLE_EQ(nf[1], 0.0);
  EXPECT_DOUBLE_EQ(nf[2], 1.0);
}

TEST(PlannerConfigYaml, ReadsKeysAndRejectsBadValues) {
  const PlannerConfig c = PlannerConfig::fromYaml(YAML::Load(
      "policy: estimated_node\nweights: {travel_distance: 0.4, battery: 0.15}\nhorizon_hops: 5\n"
      "interactions: [{criteria: [sensing_time, battery], bonus: 0.05}]\nrfid: {read_range: 2.5}\n"));
  EXPECT_EQ(c.policy, Policy::kEstimatedNode);
  EXPECT_DOUBLE_EQ(c.weights[kTravelDistance], 0.4);
  EXPECT_DOUBLE_EQ(c.weights[kRfidGain], 0.35);
  EXPECT_DOUBLE_EQ(c.weights[kBattery], 0.15);
  EXPECT_EQ(c.horizon_hops, 5);
  ASSERT_EQ(c.interactions.size(), 1u);
  EXPECT_EQ(c.interactions[0].a, std::size_t{kSensingTime});
  EXPECT_DOUBLE_EQ(c.rfid.read_range, 2.5);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("policy: random")), std::runtime_error);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("rfid: {p_detect: 1.5}")), std::runtime_error);
  EXPECT_THROW(
      PlannerConfig::fromYaml(YAML::Load("interactions: [{criteria: [speed, battery], bonus: 0.1}]")),
      std::runtime_error);
  EXPECT_THROW(PlannerConfig::fromYaml(YAML::Load("horizon_hops: lots")), std::runtime_error);
}
