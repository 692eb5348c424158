// The offline Table II runner: determinism (same seed -> same summary, whatever the number of jobs), output
// files, unavailable methods reported, any map format, ground truth equal to the simulator's.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "legacy_tmap.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/eval/experiment.h"
#include "picker_localisation/sim/farm_simulator.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;
using namespace picker_localisation::eval;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// The package's config/sim.yaml with the call scenario's mean tray time set, written into `dir`.
std::string simWithTrayTime(const fs::path& dir, double tray_time_mean) {
  const std::string sim = (dir / "sim_calls.yaml").string();
  YAML::Node y = YAML::LoadFile(resolveConfigFile("", "sim.yaml"));
  y["calls"]["tray_time_mean"] = tray_time_mean;
  std::ofstream(sim) << y;
  return sim;
}

// Writes the synthetic polytunnel as a tmap2 file (nodes, poses, edges, row tags).
std::string writeSyntheticTmap2(const fs::path& dir) {
  topology::PolytunnelSpec spec;
  spec.lanes = 6;
  spec.nodes_per_lane = 8;
  const topology::TopologicalMap map = topology::makePolytunnelMap(spec);
  std::ostringstream y;
  y << "name: synthetic_test\nmetric_map: synthetic_test\nnodes:\n";
  for (topology::NodeIndex i = 0; i < map.numNodes(); ++i) {
    const auto& n = map.node(i);
    y << "- meta:\n    node: " << n.name << "\n";
    if (!n.tags.empty()) y << "    tag: [" << n.tags[0] << "]\n";
    y << "  node:\n    name: " << n.name << "\n    pose:\n      position: {x: " << n.position.x()
      << ", y: " << n.position.y() << ", z: 0.0}\n      orientation: {x: 0, y: 0, z: 0, w: 1}\n    edges:\n";
    for (const auto& e : map.edges())
      if (e.source == i)
        y << "    - {edge_id: " << e.id << ", node: " << map.node(e.target).name << ", action: " << e.action
          << "}\n";
  }
  const fs::path path = dir / "synthetic_test.tmap2";
  std::ofstream(path) << y.str();
  return path.string();
}

fs::path tempDir(const std::string& name) {
  const fs::path p = fs::path(testing::TempDir()) / ("pl_experiment_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

}  // namespace

TEST(Experiment, MethodsAndScenarios) {
  EXPECT_EQ(allMethodNames().size(), 13u);
  EXPECT_TRUE(isKnownMethod("oracle"));
  EXPECT_EQ(parseScenario("calls"), Scenario::kCalls);
  EXPECT_EQ(defaultMethods(Scenario::kCalls),
            (std::vector<std::string>{"oracle", "raw_fix", "khan_connected", "estimated_node", "nbs"}));
  EXPECT_TRUE(isKnownMethod("ukf_metric"));
  EXPECT_TRUE(isKnownMethod("raw_fix"));
  EXPECT_TRUE(isKnownMethod("gnss_tpf"));
  EXPECT_FALSE(isKnownMethod("bogus"));
  EXPECT_EQ(methodUnavailableReason("bogus"), "unknown method");
  EXPECT_THROW(parseScenario("double"), std::invalid_argument);
  EXPECT_EQ(defaultMethods(Scenario::kNavigation), (std::vector<std::string>{"estimated_node", "nbs"}));
  EXPECT_EQ(defaultMethods(Scenario::kMulti).size(), 4u);
  EXPECT_EQ(defaultMethods(Scenario::kSingle).size(), 5u);
}

TEST(Experiment, SameSeedSameSummaryAnyJobs) {
  if (!methodUnavailableReason("khan_connected").empty())
    GTEST_SKIP() << methodUnavailableReason("khan_connected");
  const fs::path dir = tempDir("determinism");
  ExperimentConfig c;
  c.map_path = writeSyntheticTmap2(dir);
  c.scenario = Scenario::kSingle;
  c.methods = {"khan_connected", "rfid_gnss", "ukf_metric"};
  c.runs = 2;
  c.seed = 11;
  c.duration = 60.0;
  std::ostringstream log1, log2;
  c.out_dir = (dir / "a").string();
  c.jobs = 2;
  const ExperimentResult r1 = runExperiment(c, log1);
  c.out_dir = (dir / "b").string();
  c.jobs = 1;
  runExperiment(c, log2);
  const std::string s1 = slurp(dir / "a" / "summary.csv");
  EXPECT_EQ(s1, slurp(dir / "b" / "summary.csv"));
  EXPECT_EQ(slurp(dir / "a" / "khan_connected" / "run_1.csv"),
            slurp(dir / "b" / "khan_connected" / "run_1.csv"));
  EXPECT_EQ(s1.substr(0, s1.find('\n')),
            "method,runs,euclidean_mean,euclidean_std,topological_mean,topological_std,right_lane_share,"
            "right_lane_share_std");
  EXPECT_TRUE(fs::exists(dir / "a" / "summary.md"));
  EXPECT_TRUE(fs::exists(dir / "a" / "errors.png"));
  ASSERT_EQ(r1.rows.size(), 3u);
  for (const auto& row : r1.rows) {
    if (!row.available) continue;
    EXPECT_EQ(row.runs, 2u);
    EXPECT_TRUE(std::isfinite(row.euclidean_mean));
    EXPECT_GE(row.topological_mean, 0.0);
  }
  // A different seed gives different pickers, so different numbers.
  c.seed = 12;
  c.out_dir = (dir / "c").string();
  std::ostringstream log3;
  runExperiment(c, log3);
  EXPECT_NE(s1, slurp(dir / "c" / "summary.csv"));
}

TEST(Experiment, UnavailableMethodIsReportedNotRun) {
  const fs::path dir = tempDir("unavailable");
  ExperimentConfig c;
  c.map_path = std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2";
  c.scenario = Scenario::kSingle;
  c.methods = {"lidar_gnss"};
  c.runs = 1;
  c.duration = 10.0;
  c.out_dir = dir.string();
  c.run.leg_model = "/nonexistent/leg_classifier.yml";  // the LiDAR front-end cannot be built
  std::ostringstream log;
  const ExperimentResult r = runExperiment(c, log);
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_FALSE(r.rows[0].available);
  EXPECT_NE(log.str().find("lidar_gnss: UNAVAILABLE ("), std::string::npos);
  EXPECT_NE(slurp(dir / "summary.csv").find("lidar_gnss,0,unavailable,unavailable"), std::string::npos);
  EXPECT_NE(slurp(dir / "summary.md").find("unavailable: needs"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "lidar_gnss"));
  RunConfig rc = c.run;
  rc.method = "lidar_gnss";
  EXPECT_THROW(runOnce(std::make_shared<const topology::TopologicalMap>(topology::loadMap(c.map_path)), rc),
               std::runtime_error);
  c.methods = {"bogus"};
  EXPECT_THROW(runExperiment(c, log), std::invalid_argument);
}

TEST(Experiment, LegacyMapAndTruthFromTheSimulator) {
  if (!methodUnavailableReason("khan_connected").empty())
    GTEST_SKIP() << methodUnavailableReason("khan_connected");
  auto map = std::make_shared<const topology::TopologicalMap>(
      topology::loadMap(picker_localisation::test::legacyRiseholmePath()));
  RunConfig rc;
  rc.scenario = Scenario::kMulti;
  rc.method = "khan_connected";
  rc.seed = 5;
  rc.duration = 30.0;
  const RunResult r = runOnce(map, rc);
  ASSERT_FALSE(r.samples.empty());
  // The truth of a sample is the simulator's picker pose at that time (same seed; the pickers do not depend
  // on the sensors switched on). the configuration the runner (and farm_sim in demo.launch) uses:
  // config/sim.yaml + config/pickers.yaml
  const std::string sim_file = resolveConfigFile("", "sim.yaml");
  sim::SimConfig sc = sim_file.empty() ? sim::SimConfig() : sim::loadSimConfig(sim_file);
  sc.seed = 5;
  sc.num_robots = 1;
  const std::string pickers_file = resolveConfigFile("", "pickers.yaml");
  ASSERT_FALSE(pickers_file.empty());
  sc.pickers = sim::pickerSpecsFromRegistry(core::PickerRegistry::load(pickers_file));
  sc.pickers.resize(3);
  sim::FarmSimulator simulator(*map, sc);
  std::size_t checked = 0;
  for (const auto& s : r.samples) {
    if (s.stamp > simulator.time() + 1e-9) simulator.advanceTo(s.stamp);
    const std::size_t i = *simulator.pickerIndex(s.picker_id);
    EXPECT_NEAR((s.true_position - simulator.pickerPose(i).position()).norm(), 0.0, 1e-9) << s.stamp;
    EXPECT_NEAR(s.euclidean, (map->position2d(s.estimated_node) - s.true_position).norm(), 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 60u);  // 3 pickers, ~30 samples each (after the first fix)
}

TEST(Experiment, RawFixIsTheNodeNearestTheLatestFix) {
  // With every GNSS error off but a 0.1 m white noise, the raw fix's node is within half a node spacing (~1.5 m)
  // of the truth most of the time: the baseline measures the fixes, not a filter.
  const std::string sim = (fs::path(testing::TempDir()) / "pl_sim_white.yaml").string();
  {
    YAML::Node y = YAML::LoadFile(resolveConfigFile("", "sim.yaml"));
    y["gnss"]["offset_max"] = 0.0;
    y["gnss"]["drift_std"] = 0.0;
    y["gnss"]["blackout_mean_interval"] = 0.0;
    std::ofstream(sim) << y;
  }
  auto map = std::make_shared<const topology::TopologicalMap>(
      topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2"));
  RunConfig rc;
  rc.scenario = Scenario::kSingle;
  rc.method = "raw_fix";
  rc.seed = 2;
  rc.duration = 60.0;
  rc.sim_config = sim;
  const RunResult r = runOnce(map, rc);
  ASSERT_GE(r.samples.size(), 50u);
  std::size_t close = 0;
  for (const auto& s : r.samples) close += s.euclidean < 2.0 ? 1 : 0;
  EXPECT_GT(static_cast<double>(close) / r.samples.size(), 0.9);
}
// Issue "Find the lane": with Table I GNSS (2-5 m bias) the robot's LiDAR people are given to the picker, its
// bias estimate follows the simulator's true GNSS error, and a fresh estimate names the lane. Ground truth is
// used here for scoring only.
TEST(Experiment, LidarPeopleTeachTheGnssBias) {
  auto map = std::make_shared<const topology::TopologicalMap>(
      topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2"));
  RunConfig rc;
  rc.scenario = Scenario::kSingle;
  rc.method = "lidar_gnss";
  rc.seed = 1;
  rc.duration = 300.0;
  const RunResult r = runOnce(map, rc);
  ASSERT_GT(r.lidar_detections, 50u);
  EXPECT_GT(r.identified_detections, r.lidar_detections * 9 / 10);
  EXPECT_EQ(r.wrong_identifications, 0u);
  EXPECT_GT(r.bias_sightings, r.identified_detections / 2);
  std::size_t fresh = 0, fresh_right = 0, fresh_lane = 0;
  double fresh_residual = 0.0, never_residual = 0.0;
  std::size_t never = 0;
  for (const BiasSample& b : r.bias_samples) {
    if (b.sighting_age < 10.0) {
      ++fresh;
      fresh_residual += b.residual;
      if (b.lane_applicable) {
        ++fresh_lane;
        fresh_right += b.in_true_lane;
      }
    } else if (!std::isfinite(b.sighting_age)) {
      ++never;
      never_residual += b.residual;
    }
  }
  ASSERT_GT(fresh_lane, 20u);
  EXPECT_LT(fresh_residual / fresh, 1.0);  // m: the estimate is within a metre of the true error
  if (never > 0) {
    EXPECT_GT(never_residual / never, fresh_residual / fresh);
  }
  EXPECT_GT(static_cast<double>(fresh_right) / fresh_lane, 0.85);
}

TEST(Experiment, CallsScenarioScoresEveryCall) {
  // Six pickers fill trays in 60-180 s and call; two robots answer. With the true node (oracle) every call is
  // answered, none falsely; the raw fix's node sends robots into lanes the picker is not in. summary.csv has
  // the call columns.
  const fs::path dir = tempDir("calls");
  const std::string sim = simWithTrayTime(dir, 120.0);
  ExperimentConfig c;
  c.map_path = std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2";
  c.scenario = Scenario::kCalls;
  c.methods = {"oracle", "raw_fix"};
  c.runs = 2;
  c.duration = 900.0;
  c.out_dir = dir.string();
  c.jobs = 2;
  c.run.pickers = 6;
  c.run.robots = 2;
  c.run.sim_config = sim;
  std::ostringstream log;
  runExperiment(c, log);
  const std::string csv = slurp(dir / "summary.csv");
  ASSERT_EQ(csv.rfind("method,calls,arrived,arrival_s_mean,arrival_ratio_oracle,wrong_lane_entries_per_call,"
                      "false_arrivals",
                      0),
            0u)
      << csv;
  std::map<std::string, std::vector<std::string>> rows;
  std::stringstream lines(csv);
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line)) {
    std::vector<std::string> cells;
    std::stringstream cs(line);
    std::string cell;
    while (std::getline(cs, cell, ',')) cells.push_back(cell);
    rows[cells.at(0)] = cells;
  }
  ASSERT_EQ(rows.size(), 2u) << csv;
  const auto& oracle = rows.at("oracle");
  const auto& raw = rows.at("raw_fix");
  EXPECT_GE(std::stoi(oracle[1]), 20);  // 6 pickers, 900 s, 2 runs: about 6 calls each
  EXPECT_GE(std::stoi(oracle[2]),
            std::stoi(oracle[1]) - 6);  // all but the last few of each run, still queued
  EXPECT_EQ(std::stoi(oracle[6]), 0);   // no false arrival
  EXPECT_DOUBLE_EQ(std::stod(oracle[4]), 1.0);
  EXPECT_LT(std::stod(oracle[5]), 0.2);
  EXPECT_GT(std::stod(raw[5]), std::stod(oracle[5]));  // the raw fix's node is often a lane off

  // Per call, what the farm's tracker and the bias estimate said when a robot was assigned: masses are
  // shares of one belief (the picker's lane holds at most the largest lane's), the picker's lane holds most
  // of it in most calls (robots about), the last sighting is in the past.
  std::ifstream calls(dir / "oracle" / "calls_0.csv");
  std::string header;
  std::getline(calls, header);
  ASSERT_NE(header.find(",true_lane_mass,top_lane_mass,sighting_age_s,last_sighting_error_m,bias_residual_m,"
                        "wrong_identities_600s,queued_s,held_s"),
            std::string::npos)
      << header;
  std::size_t assigned = 0, mostly_right = 0;
  while (std::getline(calls, line)) {
    std::vector<std::string> cells;
    std::stringstream cs(line);
    std::string cell;
    while (std::getline(cs, cell, ',')) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 20u) << line;
    // The evidence that declared an arrival: the person's association probability, or a read at least as
    // strong as the dispatcher's arrival_min_rssi (-48 dBm).
    if (cells[8] == "lidar") {
      EXPECT_GE(std::stod(cells[9]), 0.0) << line;
      EXPECT_LE(std::stod(cells[9]), 1.0) << line;
    } else if (cells[8] == "rfid") {
      EXPECT_GE(std::stod(cells[9]), -48.0) << line;
      EXPECT_LT(std::stod(cells[9]), 0.0) << line;
    }
    const double true_lane = std::stod(cells[12]), top = std::stod(cells[13]), age = std::stod(cells[14]);
    if (std::isnan(top)) continue;  // never assigned
    ++assigned;
    EXPECT_GE(top, 0.0);
    EXPECT_LE(top, 1.0 + 1e-9);
    if (!std::isnan(true_lane)) {
      EXPECT_LE(true_lane, top + 1e-9) << line;
    }
    if (true_lane > 0.5) ++mostly_right;
    EXPECT_GE(age, 0.0) << line;
    const double sighting_error = std::stod(cells[15]);  // NaN: the last sighting was a tag read, or none
    if (!std::isnan(sighting_error)) {
      EXPECT_GE(sighting_error, 0.0) << line;
    }
    const double residual = std::stod(cells[16]);
    if (!std::isnan(residual)) {
      EXPECT_GE(residual, 0.0) << line;
    }
    EXPECT_GE(std::stod(cells[18]), 0.0) << line;  // queued until assigned
    EXPECT_EQ(std::stod(cells[19]), 0.0) << line;  // the oracle's one node is one lane: never held at its end
  }
  EXPECT_GE(assigned, 5u);
  EXPECT_GT(mostly_right * 2, assigned);
}

TEST(Experiment, IdleRobotsArePositionedByThePlanner) {
  // Nobody calls (trays take hours): every robot is idle. With idle_robots "nbs" the planner sends them
  // where their sensors tell most about the pickers, as nbs_planner does in the ROS graph, so they see and
  // identify more pickers than robots waiting where they started; with "stay" no goal is given.
  const std::string sim = simWithTrayTime(tempDir("idle"), 1.0e6);
  auto map = std::make_shared<const topology::TopologicalMap>(
      topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2"));
  RunConfig rc;
  rc.scenario = Scenario::kCalls;
  rc.method = "nbs";
  rc.seed = 3;
  rc.duration = 300.0;
  rc.pickers = 6;
  rc.robots = 2;
  rc.sim_config = sim;
  rc.idle_robots = "stay";
  const RunResult stay = runOnce(map, rc);
  rc.idle_robots = "nbs";
  const RunResult planned = runOnce(map, rc);
  EXPECT_TRUE(stay.calls.empty());
  EXPECT_EQ(stay.idle_goals, 0u);
  EXPECT_GE(planned.idle_goals, 2u);  // at least one goal per robot
  EXPECT_GT(planned.identified_detections, stay.identified_detections);
  rc.idle_robots = "wander";
  EXPECT_THROW(runOnce(map, rc), std::runtime_error);
}
