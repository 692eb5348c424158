// Shared contracts: Gaussian node likelihoods, observation validation, the picker registry.
#include <gtest/gtest.h>

#include <cmath>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;
using namespace picker_localisation::core;
using topology::NodeIndex;

TEST(GaussianLikelihood, ValuesAndSupport) {
  topology::PolytunnelSpec spec;  // lane k at x = 1.5 k, nodes every 3 m along y
  topology::TopologicalMap map = topology::makePolytunnelMap(spec);
  Observation obs;
  const Eigen::Vector2d mean(3.0, 6.0);  // exactly on r2_2
  setGaussianLikelihood(obs, map, mean, Eigen::Matrix2d::Identity() * 1.0);
  ASSERT_EQ(obs.nodes.size(), obs.likelihood.size());
  for (std::size_t i = 0; i < obs.nodes.size(); ++i) {
    const double d = (map.position2d(obs.nodes[i]) - mean).norm();
    EXPECT_LE(d, 3.0 + 1e-9);                                   // 3 sigma cut-off
    EXPECT_NEAR(obs.likelihood[i], std::exp(-0.5 * d * d), 1e-12);  // hand formula, unit covariance
  }
  NodeIndex on = *map.index("r2_2");
  auto it = std::find(obs.nodes.begin(), obs.nodes.end(), on);
  ASSERT_NE(it, obs.nodes.end());
  EXPECT_DOUBLE_EQ(obs.likelihood[static_cast<std::size_t>(it - obs.nodes.begin())], 1.0);
  EXPECT_EQ(validateObservation(obs, map), "");
}

TEST(GaussianLikelihood, FarAwayFallsBackToNearestNodeAndSigmaFloor) {
  topology::TopologicalMap map = topology::makePolytunnelMap(topology::PolytunnelSpec{});
  Observation obs;
  setGaussianLikelihood(obs, map, Eigen::Vector2d(-500.0, 0.0), Eigen::Matrix2d::Identity() * 0.01);
  ASSERT_EQ(obs.nodes.size(), 1u);
  EXPECT_EQ(obs.nodes[0], map.nearestNode(Eigen::Vector2d(-500.0, 0.0)));
  EXPECT_GT(obs.likelihood[0], 0.0);
  // A zero covariance with a 2 m floor still spreads over neighbours.
  GaussianLikelihoodOptions o;
  o.min_sigma = 2.0;
  setGaussianLikelihood(obs, map, Eigen::Vector2d(3.0, 6.0), Eigen::Matrix2d::Zero(), o);
  EXPECT_GT(obs.nodes.size(), 3u);
  o.max_nodes = 2;
  setGaussianLikelihood(obs, map, Eigen::Vector2d(3.0, 6.0), Eigen::Matrix2d::Zero(), o);
  EXPECT_EQ(obs.nodes.size(), 2u);
}

TEST(ObservationValidation, RejectsBadInput) {
  topology::TopologicalMap map = topology::makePolytunnelMap(topology::PolytunnelSpec{});
  Observation obs;
  obs.nodes = {0, 1};
  obs.likelihood = {0.5, 0.5};
  EXPECT_EQ(validateObservation(obs, map), "");
  Observation bad = obs;
  bad.likelihood[1] = std::nan("");
  EXPECT_NE(validateObservation(bad, map), "");
  bad = obs;
  bad.nodes[1] = static_cast<NodeIndex>(map.numNodes());
  EXPECT_NE(validateObservation(bad, map), "");
  bad = obs;
  bad.likelihood = {0.0, 0.0};
  EXPECT_NE(validateObservation(bad, map), "");
  bad = obs;
  bad.nodes = {1, 1};
  EXPECT_NE(validateObservation(bad, map), "");
  bad = obs;
  bad.identifying = true;
  EXPECT_NE(validateObservation(bad, map), "");
  bad = Observation();
  EXPECT_EQ(validateObservation(bad, map), "empty likelihood");
}

TEST(PickerRegistry, ShippedConfigAndLookups) {
  PickerRegistry r = PickerRegistry::load(std::string(PL_PACKAGE_DIR) + "/config/pickers.yaml");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r.ids(), (std::vector<std::string>{"picker_1", "picker_2", "picker_3"}));
  EXPECT_EQ(r.pickerForRfidTag("rfid_0002").value(), "picker_2");
  EXPECT_EQ(r.pickerForUwbTag("uwb_0003").value(), "picker_3");
  EXPECT_FALSE(r.pickerForRfidTag("nope").has_value());
  EXPECT_FALSE(r.pickerForUwbTag("").has_value());
  EXPECT_EQ(r.find("picker_1")->gnss_topic, "/pickers/picker_1/fix");
  EXPECT_EQ(r.find("ghost"), nullptr);
}

TEST(PickerRegistry, BadFiles) {
  EXPECT_THROW(PickerRegistry::parse("pickers: [{gnss_topic: x}]"), std::runtime_error);
  EXPECT_THROW(PickerRegistry::parse("pickers: [{id: a}, {id: a}]"), std::runtime_error);
  EXPECT_THROW(PickerRegistry::parse("pickers: [{id: a, rfid_tags: [t]}, {id: b, rfid_tags: [t]}]"), std::runtime_error);
  EXPECT_THROW(PickerRegistry::parse("pickers: [{id: a, uwb_tag: u}, {id: b, uwb_tag: u}]"), std::runtime_error);
  EXPECT_THROW(PickerRegistry::parse("[1, 2]"), std::runtime_error);
  EXPECT_THROW(PickerRegistry::parse("pickers: [{id: a, rfid_tags: {x: 1}}]"), std::runtime_error);
  EXPECT_THROW(PickerRegistry::load("/nonexistent.yaml"), std::runtime_error);
  try {
    PickerRegistry::parse("pickers: [{id: a}, {id: a}]", "p.yaml");
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("p.yaml: duplicate picker id 'a'"), std::string::npos) << e.what();
  }
}

// Issue "Track a whole farm": ids must name topics, tags must not be empty; run-time add / remove change
// nothing on a refusal; a file entry's tpf overrides are kept as YAML.
TEST(PickerRegistry, IdsTagsAndRunTimeChanges) {
  EXPECT_EQ(pickerIdProblem("picker_1"), "");
  EXPECT_NE(pickerIdProblem(""), "");
  EXPECT_NE(pickerIdProblem("1st"), "");
  EXPECT_NE(pickerIdProblem("bad-id"), "");
  EXPECT_NE(pickerIdProblem("a/b"), "");
  EXPECT_EQ(pickerIdProblem("p" + std::string(kMaxPickerIdLength - 1, 'x')), "");
  const std::string long_problem = pickerIdProblem("p" + std::string(10000, 'x'));
  EXPECT_NE(long_problem.find("longer than 64"), std::string::npos) << long_problem;
  EXPECT_LT(long_problem.size(), 200u) << "the whole id quoted";
  // One GNSS device per picker: two pickers on one topic would each take the other's fixes.
  EXPECT_THROW(PickerRegistry::parse("pickers: [{id: a, gnss_topic: /f}, {id: b, gnss_topic: /f}]"),
               std::runtime_error);
  EXPECT_NO_THROW(PickerRegistry::parse("pickers: [{id: a, gnss_topic: ''}, {id: b, gnss_topic: ''}]"));
  EXPECT_THROW(PickerRegistry::parse("pickers: [{id: bad-id}]"), std::runtime_error);
  EXPECT_THROW(PickerRegistry::parse("pickers: [{id: a, rfid_tags: ['']}]"), std::runtime_error);
  EXPECT_THROW(PickerRegistry::parse("pickers: [{id: a, tpf: 3}]"), std::runtime_error);
  PickerRegistry r = PickerRegistry::parse("pickers: [{id: a, rfid_tags: [t1], tpf: {num_particles: 200}}, {id: b}]");
  EXPECT_NE(r.find("a")->tpf_overrides.find("num_particles: 200"), std::string::npos);
  EXPECT_EQ(r.find("b")->tpf_overrides, "");
  PickerConfig c;
  c.id = "c";
  c.rfid_tags = {"t1"};  // worn by a
  EXPECT_THROW(r.add(c), std::runtime_error);
  c.id = "a";
  c.rfid_tags = {"t3"};
  EXPECT_THROW(r.add(c), std::runtime_error);  // duplicate id
  EXPECT_EQ(r.ids(), (std::vector<std::string>{"a", "b"}));
  c.id = "c";
  r.add(c);
  EXPECT_EQ(r.ids(), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(r.pickerForRfidTag("t3"), std::optional<std::string>("c"));
  EXPECT_FALSE(r.remove("zz"));
  EXPECT_TRUE(r.remove("a"));
  EXPECT_EQ(r.ids(), (std::vector<std::string>{"b", "c"}));
  EXPECT_FALSE(r.pickerForRfidTag("t1"));
}

#include "picker_localisation/core/stamp_ordered_buffer.h"

TEST(StampOrderedBuffer, ReleasesInStampOrderAfterLatencyWhateverTheArrivalOrder) {
  // Two arrival orders of the same messages release the same sequence.
  const std::vector<std::tuple<double, std::string, int>> msgs{
      {1.0, "gnss", 1}, {0.9, "lidar", 2}, {1.0, "camera", 3}, {2.5, "gnss", 4}, {1.2, "rfid", 5}};
  auto run = [&](std::vector<std::size_t> order) {
    StampOrderedBuffer<int> b(0.5);
    std::vector<int> seen;
    double now = 0.0;
    for (std::size_t k : order) {
      b.push(std::get<0>(msgs[k]), std::get<1>(msgs[k]), std::get<2>(msgs[k]));
      now += 0.3;
      for (auto& [stamp, v] : b.release(now)) {
        EXPECT_LE(stamp, now - 0.5);
        seen.push_back(v);
      }
    }
    for (auto& [stamp, v] : b.releaseAll()) seen.push_back(v);
    return seen;
  };
  const std::vector<int> want{2, 3, 1, 5, 4};  // by stamp, ties by key ("camera" < "gnss")
  EXPECT_EQ(run({0, 1, 2, 3, 4}), want);
  EXPECT_EQ(run({4, 3, 2, 1, 0}), want);
  EXPECT_EQ(run({2, 0, 4, 1, 3}), want);
}

TEST(StampOrderedBuffer, HoldsUntilLatencyAndBoundsMemory) {
  StampOrderedBuffer<int> b(1.0, 3);
  b.push(10.0, "a", 1);
  EXPECT_TRUE(b.release(10.5).empty());
  EXPECT_EQ(b.release(11.0).size(), 1u);
  for (int i = 0; i < 5; ++i) b.push(20.0 + i, "a", i);
  auto out = b.release(0.0);  // over the bound: the two oldest are forced out
  ASSERT_EQ(out.size(), 2u);
  EXPECT_DOUBLE_EQ(out[0].first, 20.0);
  EXPECT_EQ(b.forcedReleases(), 2u);
  EXPECT_EQ(b.size(), 3u);
}

#include <cstdio>
#include <fstream>

#include "picker_localisation/core/yaml_file.h"

TEST(YamlFile, ParsesAndNamesTheFileInEveryError) {
  char name[] = "yaml_file_testXXXXXX";
  const int fd = mkstemp(name);
  ASSERT_GE(fd, 0);
  const std::string path = name;
  std::ofstream(path) << "a: 3\n";
  EXPECT_EQ(parseYamlFile(path, [](const YAML::Node& n) { return n["a"].as<int>(); }), 3);
  try {  // the parser's own error gets the path in front
    parseYamlFile(path, [](const YAML::Node&) -> int { throw std::runtime_error("bad key 'a'"); });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": bad key 'a'");
  }
  std::ofstream(path) << "a: [\n";  // YAML syntax error
  try {
    parseYamlFile(path, [](const YAML::Node&) { return 0; });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
  }
  EXPECT_THROW(parseYamlFile(path + ".missing", [](const YAML::Node&) { return 0; }), std::runtime_error);
  std::remove(path.c_str());
}

// The one 2x2 covariance check: finite, symmetric, PSD up to a tolerance relative to the largest entry.
TEST(Covariance2d, OneCheckForEveryNode) {
  using picker_localisation::core::isCovariance2d;
  EXPECT_TRUE(isCovariance2d(Eigen::Matrix2d::Identity()));
  EXPECT_TRUE(isCovariance2d(Eigen::Matrix2d::Zero()));
  Eigen::Matrix2d rank1;
  rank1 << 1e4 / 3.0, 1e4 / 3.0 * std::sqrt(3.0), 1e4 / 3.0 * std::sqrt(3.0), 1e4;  // det 0 up to rounding
  EXPECT_TRUE(isCovariance2d(rank1));
  Eigen::Matrix2d c = Eigen::Matrix2d::Identity();
  c(0, 0) = -4.0;
  EXPECT_FALSE(isCovariance2d(c));  // a negative variance
  c << 1.0, 2.0, 2.0, 1.0;
  EXPECT_FALSE(isCovariance2d(c));  // determinant -3
  c << 1.0, 0.5, 0.0, 1.0;
  EXPECT_FALSE(isCovariance2d(c));  // not symmetric
  c << 1.0, 0.0, 0.0, std::nan("");
  EXPECT_FALSE(isCovariance2d(c));
}
