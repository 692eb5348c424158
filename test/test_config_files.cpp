// Every shipped config/*.yaml through every reader that uses it: a key renamed in a
// reader but not in its file (or the other way round) fails here, in CI, not on the robot. A reader with an
// unknown-key check must report none for the shipped file; every file must load and validate.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/core/node_options.h"
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
  // Readers without an unknown-key check of their own: they must load and validate.
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

// The keys every node shares have one name each; the names used before are still read for one release, each
// with a warning, and a shipped file uses none of them.
TEST(ConfigFiles, SharedNodeKeysHaveOneNameAndTheOldOnesWarn) {
  std::vector<std::string> warnings;
  core::CommonNodeOptions defaults;
  defaults.tf_timeout = 0.1;
  const auto o = core::CommonNodeOptions::fromYaml(
      YAML::Load("{frame_id: odom, observation_topic: /obs, max_future_stamp: 3}"), "gnss_ingest", &warnings,
      defaults);
  EXPECT_EQ(o.map_frame, "odom");
  EXPECT_EQ(o.observations_topic, "/obs");
  EXPECT_DOUBLE_EQ(o.max_future_stamp, 3.0);
  EXPECT_DOUBLE_EQ(o.tf_timeout, 0.1);  // the node's own default
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("'frame_id' is deprecated, use 'map_frame'"), std::string::npos) << warnings[0];
  warnings.clear();
  // Both names: the new one is used, and the warning says so.
  const auto both = core::CommonNodeOptions::fromYaml(YAML::Load("{fixed_frame: odom, map_frame: map}"),
                                                      "leg_detector", &warnings, {});
  EXPECT_EQ(both.map_frame, "map");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("both are set"), std::string::npos) << warnings[0];
  // A bad value names the key; a value of the wrong type too.
  EXPECT_THROW(core::CommonNodeOptions::fromYaml(YAML::Load("{max_future_stamp: -1}"), "x", nullptr, {}),
               std::runtime_error);
  EXPECT_THROW(core::CommonNodeOptions::fromYaml(YAML::Load("{tf_timeout: soon}"), "x", nullptr, {}),
               std::runtime_error);
  // No shipped file uses an old name.
  for (const auto& entry : std::filesystem::directory_iterator(std::string(PL_PACKAGE_DIR) + "/config")) {
    if (entry.path().extension() != ".yaml") continue;
    const YAML::Node root = YAML::LoadFile(entry.path().string());
    std::vector<YAML::Node> maps{root};
    if (root.IsMap())
      for (const auto& kv : root)
        if (kv.second.IsMap()) maps.push_back(kv.second);  // vision.yaml's per-node sections
    for (const YAML::Node& m : maps)
      for (const auto& [old_name, name] : core::CommonNodeOptions::deprecatedKeys())
        EXPECT_FALSE(m.IsMap() && m[old_name])
            << entry.path() << " uses '" << old_name << "': use '" << name << "'";
  }
}
