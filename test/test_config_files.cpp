// Every shipped config/*.yaml through every reader that uses it (issue "One options schema"): a key renamed in a
// reader but not in its file (or the other way round) fails here, in CI, not on the robot. A reader with an
// unknown-key check must report none for the shipped file; every file must load and validate.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/dispatch/dispatcher_node_options.h"
#include "picker_localisation/nbs/next_best_sense_planner.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "picker_localisation/sensors_ranging/rfid_observation_model.h"
#include "picker_localisation/sensors_ranging/uwb_ranging.h"
#include "picker_localisation/sensors_vision/leg_pipeline.h"
#include "picker_localisation/sensors_vision/person_box_detector.h"
#include "picker_localisation/sim/farm_simulator.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/tpf/tpf_params.h"

using namespace picker_localisation;

namespace {
std::string config(const std::string& name) { return std::string(PL_PACKAGE_DIR) + "/config/" + name; }
std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}
}  // namespace

TEST(ConfigFiles, EveryShippedFileLoadsThroughItsReadersWithoutUnknownKeys) {
  std::set<std::string> covered;
  auto use = [&](const std::string& name) {
    covered.insert(name);
    return config(name);
  };
  std::vector<std::string> unknown;
  EXPECT_NO_THROW(tpf::TpfParams::fromYamlFile(use("tpf.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(sensors::GnssIngestOptions::fromYamlFile(use("gnss_ingest.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(sensors::RfidModelOptions::fromYamlFile(use("rfid_ranging.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(sensors::UwbRangingOptions::fromYamlFile(use("uwb_ranging.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  // leg_detector loads vision.yaml; the simulator's launch files and the runner put vision_sim.yaml over it.
  EXPECT_NO_THROW(vision::LegPipelineOptions::fromYamlFiles({use("vision.yaml")}, &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(vision::LegPipelineOptions::fromYamlFiles({config("vision.yaml"), use("vision_sim.yaml")}, &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(vision::CameraDetectorOptions::fromYamlFile(config("vision.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(nbs::PlannerConfig::fromYamlFile(use("nbs.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(
      dispatch::DispatcherNodeOptions::fromYaml(YAML::LoadFile(use("dispatcher.yaml")), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  // No unknown-key check in these readers yet (issue "One options schema"): they must load and validate.
  EXPECT_NO_THROW(sim::loadSimConfig(use("sim.yaml")));  // throws on an unknown key itself
  EXPECT_NO_THROW(core::GeodeticDatum::load(use("datum.yaml")));
  EXPECT_NO_THROW(core::PickerRegistry::load(use("pickers.yaml")));
  EXPECT_NO_THROW(topology::loadMap(config("maps/riseholme.tmap2")));
  // Every YAML file in config/ is covered above.
  for (const auto& entry : std::filesystem::directory_iterator(std::string(PL_PACKAGE_DIR) + "/config")) {
    if (entry.path().extension() != ".yaml") continue;
    EXPECT_EQ(covered.count(entry.path().filename().string()), 1u) << entry.path() << " is read by no test";
  }
}

TEST(ConfigFiles, TpfParamsWarnAboutATypoAndNameTheKey) {
  std::vector<std::string> unknown;
  const tpf::TpfParams p = tpf::TpfParams::fromYaml(YAML::Load("{num_particle: 10, reverse_rate: 0.02}"), &unknown);
  EXPECT_DOUBLE_EQ(p.reverse_rate, 0.02);
  EXPECT_EQ(p.num_particles, tpf::TpfParams().num_particles);  // the typo changed nothing
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_NE(unknown[0].find("'num_particle'"), std::string::npos) << unknown[0];
  EXPECT_NE(unknown[0].find("did you mean 'num_particles'"), std::string::npos) << unknown[0];
  // The planner: a typo at the top and in a section.
  unknown.clear();
  nbs::PlannerConfig::fromYaml(YAML::Load("{horizon_hop: 3, energy: {capacty: 1.0}, planning_period: 5}"),
                               &unknown);
  ASSERT_EQ(unknown.size(), 2u) << joined(unknown);
  EXPECT_NE(unknown[0].find("did you mean 'horizon_hops'"), std::string::npos) << unknown[0];
  EXPECT_NE(unknown[1].find("nbs config: energy: unknown key 'capacty' (did you mean 'capacity'?)"),
            std::string::npos)
      << unknown[1];
  // Every key of the shipped file is a known key (the list is not stale either way).
  const YAML::Node shipped = YAML::LoadFile(config("tpf.yaml"));
  for (const auto& kv : shipped) {
    const std::string key = kv.first.as<std::string>();
    EXPECT_NE(std::find(tpf::TpfParams::yamlKeys().begin(), tpf::TpfParams::yamlKeys().end(), key),
              tpf::TpfParams::yamlKeys().end())
        << key;
  }
}
