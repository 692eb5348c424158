// Every shipped config/*.yaml through every reader that uses it: a key renamed in a
// reader but not in its file (or the other way round) fails here, in CI, not on the robot. A reader with an
// unknown-key check must report none for the shipped file; every file must load and validate.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/core/node_options.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/dispatch/dispatcher_node_options.h"
#include "picker_localisation/nbs/nbs_planner_node_options.h"
#include "picker_localisation/ros/evaluator_node.h"
#include "picker_localisation/ros/farm_sim_node.h"
#include "picker_localisation/sensors_ranging/ranging_node_options.h"
#include "picker_localisation/sensors_ranging/rfid_observation_model.h"
#include "picker_localisation/sensors_ranging/uwb_ranging.h"
#include "picker_localisation/sensors_vision/leg_detector_node_options.h"
#include "picker_localisation/sensors_vision/person_box_detector.h"
#include "picker_localisation/sim/farm_simulator.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/topology/map_server_options.h"
#include "picker_localisation/tpf/tpf_params.h"
#include "picker_localisation/tpf/tpf_tracker_node_options.h"

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
  EXPECT_NO_THROW(sensors::GnssIngestNodeOptions::fromYamlFile(use("gnss_ingest.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(sensors::RfidRangingNodeOptions::fromYamlFile(use("rfid_ranging.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(sensors::UwbRangingNodeOptions::fromYamlFile(use("uwb_ranging.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  // leg_detector loads vision.yaml; the simulator's launch files and the runner put vision_sim.yaml over it.
  EXPECT_NO_THROW(vision::LegDetectorNodeOptions::fromYamlFiles({use("vision.yaml")}, &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(vision::LegDetectorNodeOptions::fromYamlFiles(
      {config("vision.yaml"), use("vision_sim.yaml")}, &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(vision::CameraDetectorOptions::fromYamlFile(config("vision.yaml"), &unknown));
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
  unknown.clear();
  EXPECT_NO_THROW(nbs::NbsPlannerNodeOptions::fromYamlFile(use("nbs.yaml"), &unknown));
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
  nbs::NbsPlannerNodeOptions::fromYaml(
      YAML::Load("{horizon_hop: 3, energy: {capacty: 1.0}, planning_period: 5}"), &unknown);
  ASSERT_EQ(unknown.size(), 2u) << joined(unknown);
  EXPECT_NE(unknown[0].find("did you mean 'horizon_hops'"), std::string::npos) << unknown[0];
  EXPECT_NE(unknown[1].find("nbs config: energy: unknown key 'capacty' (did you mean 'capacity'?)"),
            std::string::npos)
      << unknown[1];
  // Every key of the shipped file is a known key of the tracker (the list is not stale either way).
  unknown.clear();
  tpf::TpfTrackerNodeOptions::fromYaml(YAML::LoadFile(config("tpf.yaml")), &unknown);
  EXPECT_TRUE(unknown.empty()) << joined(unknown);
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

namespace {

// A node, the page and heading of its reference section, its options table and its shipped config file.
struct NodeReference {
  std::string node, page, heading;
  std::vector<std::string> keys;
  std::string config_file;  // "" none
};

std::vector<NodeReference> nodeReferences() {
  std::vector<std::string> map_server = topology::MapServerOptions::yamlKeys();
  map_server.insert(map_server.end(), {"map_file", "map_frame"});
  return {
      {"gnss_ingest", "sensors_ranging.md", "## gnss_ingest", sensors::GnssIngestNodeOptions::yamlKeys(),
       "gnss_ingest.yaml"},
      {"rfid_ranging", "sensors_ranging.md", "## rfid_ranging", sensors::RfidRangingNodeOptions::yamlKeys(),
       "rfid_ranging.yaml"},
      {"uwb_ranging", "sensors_ranging.md", "## uwb_ranging", sensors::UwbRangingNodeOptions::yamlKeys(),
       "uwb_ranging.yaml"},
      {"leg_detector", "sensors_vision.md", "## Node `leg_detector`",
       vision::LegDetectorNodeOptions::yamlKeys(), "vision.yaml"},
      {"camera_detector", "sensors_vision.md", "## Node `camera_detector`",
       vision::CameraDetectorOptions::yamlKeys(), "vision.yaml"},
      {"tpf_tracker", "tpf.md", "## Node `tpf_tracker`", tpf::TpfTrackerNodeOptions::yamlKeys(), "tpf.yaml"},
      {"nbs_planner", "nbs.md", "## Node `nbs_planner`", nbs::NbsPlannerNodeOptions::yamlKeys(), "nbs.yaml"},
      {"dispatcher", "dispatch.md", "## The `dispatcher` node", dispatch::DispatcherNodeOptions::yamlKeys(),
       "dispatcher.yaml"},
      {"topological_map_server", "intro.md", "### topological_map_server", map_server, ""},
      {"farm_sim", "sim.md", "## Node `farm_sim`", ros_adapter::FarmSimOptions::yamlKeys(), ""},
      {"evaluator", "eval.md", "## Node `evaluator`", ros_adapter::EvaluatorOptions::yamlKeys(), ""},
      {"every node", "robot.md", "## Parameters every node shares", core::CommonNodeOptions::yamlKeys(), ""},
  };
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// From the heading line to the next heading of the same or a higher level ("" when the heading is missing).
std::string sectionOf(const std::string& text, const std::string& heading) {
  std::size_t at = text.find("\n" + heading);
  if (at == std::string::npos) return "";
  const std::size_t level = heading.find_first_not_of('#');
  std::size_t end = at + 1;
  while ((end = text.find("\n#", end + 1)) != std::string::npos) {
    const std::size_t hashes = text.find_first_not_of('#', end + 1) - (end + 1);
    if (hashes <= level) break;
  }
  return text.substr(at, end == std::string::npos ? std::string::npos : end - at);
}

}  // namespace

// Every key a node reads is a row of its page's Parameters table and a line of its shipped YAML (commented
// out where a launch file sets it): a key added in code and missing in either fails here.
TEST(NodeReference, EveryKeyOfANodeIsInItsPageTableAndItsYaml) {
  for (const NodeReference& n : nodeReferences()) {
    ASSERT_FALSE(n.keys.empty()) << n.node;
    const std::string page = std::string(PL_PACKAGE_DIR) + "/docs/readme/" + n.page;
    const std::string section = sectionOf(readText(page), n.heading);
    ASSERT_FALSE(section.empty()) << page << " has no section '" << n.heading << "'";
    EXPECT_NE(section.find("Parameters"), std::string::npos)
        << n.page << " " << n.heading << ": no Parameters table";
    for (const std::string& key : n.keys)
      EXPECT_NE(section.find("\n| `" + key + "` |"), std::string::npos)
          << n.page << ", " << n.heading << ": no Parameters row for '" << key << "'";
    if (n.config_file.empty()) continue;
    const std::string yaml = readText(config(n.config_file));
    for (const std::string& key : n.keys) {
      const std::regex line("(^|\\n)[ \\t]*#?[ \\t]*" + key + ":");
      EXPECT_TRUE(std::regex_search(yaml, line))
          << "config/" << n.config_file << " has no line for " << n.node << "'s key '" << key << "'";
    }
  }
}

// Each node's schema: the defaults are valid, a typo is named with the closest key, a bad value is refused.
TEST(NodeReference, EveryNodeSchemaNamesATypoAndRefusesABadValue) {
  auto check = [](const char* node, auto from_yaml, const char* typo, const char* meant, const char* bad) {
    std::vector<std::string> messages;
    EXPECT_NO_THROW(from_yaml(YAML::Load("{}"), &messages)) << node;
    EXPECT_TRUE(messages.empty()) << node << ": " << joined(messages);
    from_yaml(YAML::Load(std::string("{") + typo + ": 1}"), &messages);
    ASSERT_EQ(messages.size(), 1u) << node << ": " << joined(messages);
    EXPECT_NE(messages[0].find(std::string("did you mean '") + meant + "'"), std::string::npos)
        << messages[0];
    EXPECT_THROW(from_yaml(YAML::Load(bad), nullptr), std::runtime_error) << node << ": " << bad;
  };
  check("gnss_ingest", sensors::GnssIngestNodeOptions::fromYaml, "max_people_per_mesage",
        "max_people_per_message", "{people_pose_sigma: 0}");
  check("rfid_ranging", sensors::RfidRangingNodeOptions::fromYaml, "silent_warn_afte", "silent_warn_after",
        "{silent_warn_after: -1}");
  check("uwb_ranging", sensors::UwbRangingNodeOptions::fromYaml, "flush_perod", "flush_period",
        "{flush_period: 0}");
  check("leg_detector", vision::LegDetectorNodeOptions::fromYaml, "max_beam", "max_beams", "{max_beams: -1}");
  check("tpf_tracker", tpf::TpfTrackerNodeOptions::fromYaml, "topic_prefx", "topic_prefix", "{seed: -2}");
  check("nbs_planner", nbs::NbsPlannerNodeOptions::fromYaml, "planing_period", "planning_period",
        "{battery_level: 2}");
  check("topological_map_server", topology::MapServerOptions::fromYaml, "node_scal", "node_scale",
        "{node_scale: 0}");
  // A list given as one string (rosrun _scan_topics:="a b") is split.
  const auto legs = vision::LegDetectorNodeOptions::fromYaml(YAML::Load("{scan_topics: 'front rear'}"));
  EXPECT_EQ(legs.scan_topics, (std::vector<std::string>{"front", "rear"}));
}
