#include "picker_localisation/sensors_ranging/ranging_node_options.h"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "picker_localisation/core/option_table.h"
#include "picker_localisation/core/yaml_file.h"

namespace picker_localisation {
namespace sensors {

namespace {

using core::FleetTopicOptions;

// The shared keys over the node's defaults, the node's table, the algorithm's keys, then the unknown-key
// check over all three: what every front-end's fromYaml does.
template <class NodeOptions, class ReadAlgorithm>
NodeOptions readNode(const YAML::Node& node, const std::string& component,
                     const core::OptionTable<NodeOptions>& table,
                     const std::vector<std::string>& algorithm_keys, std::vector<std::string>* messages,
                     ReadAlgorithm read_algorithm) {
  NodeOptions o;
  o.common = core::CommonNodeOptions::fromYaml(node, component, messages, o.common);
  table.read(node, component, o);
  read_algorithm(o);
  return core::checkOptions(
      o, node, core::joinKeys({table.keys(), core::CommonNodeOptions::acceptedKeys(), algorithm_keys}),
      component, messages);
}

template <class Options>
Options fromFile(const std::string& path, std::vector<std::string>* messages) {
  return core::parseYamlFile(path, [&](const YAML::Node& root) { return Options::fromYaml(root, messages); });
}

// ---- gnss_ingest

const core::OptionTable<GnssIngestNodeOptions>& gnssTable() {
  using O = GnssIngestNodeOptions;
  static const core::OptionTable<O> table =
      core::OptionTable<O>()
          .add("pickers_file", &O::fleet, &FleetTopicOptions::pickers_file)
          .add("datum_file", &O::datum_file)
          .add("datum_source", &O::datum_source)
          .add("person_observation_topic", &O::person_observation_topic)
          .add("bias_topic_prefix", &O::bias_topic_prefix)
          .add("people_pose_topics", &O::people_pose_topics)
          .add("people_pose_sensor", &O::people_pose_sensor)
          .add("people_pose_sigma", &O::people_pose_sigma)
          .add("pose_topic_format", &O::pose_topic_format)
          .add("pose_sensor", &O::pose_sensor)
          .add("max_people_per_message", &O::max_people_per_message)
          .add("belief_topic", &O::fleet, &FleetTopicOptions::belief_topic)
          .add("registry_topic", &O::fleet, &FleetTopicOptions::registry_topic)
          .add("registry_publisher", &O::fleet, &FleetTopicOptions::registry_publisher)
          .add("on_demand_topics_above", &O::fleet, &FleetTopicOptions::on_demand_topics_above)
          .add("demand_poll_period", &O::fleet, &FleetTopicOptions::demand_poll_period)
          .add("silent_warn_after", &O::fleet, &FleetTopicOptions::silent_warn_after);
  return table;
}

// ---- rfid_ranging

const core::OptionTable<RfidRangingNodeOptions>& rfidTable() {
  using O = RfidRangingNodeOptions;
  static const core::OptionTable<O> table =
      core::OptionTable<O>()
          .add("pickers_file", &O::fleet, &FleetTopicOptions::pickers_file)
          .add("rfid_topics", &O::rfid_topics)
          .add("registry_topic", &O::fleet, &FleetTopicOptions::registry_topic)
          .add("registry_publisher", &O::fleet, &FleetTopicOptions::registry_publisher)
          .add("silent_warn_after", &O::fleet, &FleetTopicOptions::silent_warn_after);
  return table;
}

// ---- uwb_ranging

const core::OptionTable<UwbRangingNodeOptions>& uwbTable() {
  using O = UwbRangingNodeOptions;
  static const core::OptionTable<O> table =
      core::OptionTable<O>()
          .add("pickers_file", &O::fleet, &FleetTopicOptions::pickers_file)
          .add("base_frame", &O::base_frame)
          .add("uwb_topics", &O::uwb_topics)
          .add("bearing_topics", &O::bearing_topics)
          .add("flush_period", &O::flush_period)
          .add("registry_topic", &O::fleet, &FleetTopicOptions::registry_topic)
          .add("registry_publisher", &O::fleet, &FleetTopicOptions::registry_publisher)
          .add("silent_warn_after", &O::fleet, &FleetTopicOptions::silent_warn_after);
  return table;
}

}  // namespace

std::string GnssIngestNodeOptions::validate() const {
  std::string problem = common.validate();
  if (problem.empty()) problem = fleet.validate();
  if (!problem.empty()) return problem;
  if (datum_source != "auto" && datum_source != "file" && datum_source != "map")
    return "datum_source = " + datum_source + ": must be auto, file or map";
  if (!(people_pose_sigma > 0.0) || !std::isfinite(people_pose_sigma))
    return core::badValue("people_pose_sigma", people_pose_sigma, "finite and > 0");
  if (people_pose_sensor.empty()) return "people_pose_sensor: must not be empty";
  if (pose_sensor.empty()) return "pose_sensor: must not be empty";
  if (max_people_per_message < 1)
    return core::badValue("max_people_per_message", max_people_per_message, ">= 1");
  return ingest.validate();
}

const std::vector<std::string>& GnssIngestNodeOptions::yamlKeys() {
  return gnssTable().keys();
}

GnssIngestNodeOptions GnssIngestNodeOptions::fromYaml(const YAML::Node& node,
                                                      std::vector<std::string>* messages) {
  return readNode(node, "gnss_ingest", gnssTable(), GnssIngestOptions::yamlKeys(), messages,
                  [&](GnssIngestNodeOptions& o) { o.ingest = GnssIngestOptions::fromYaml(node); });
}

GnssIngestNodeOptions GnssIngestNodeOptions::fromYamlFile(const std::string& path,
                                                          std::vector<std::string>* messages) {
  return fromFile<GnssIngestNodeOptions>(path, messages);
}

std::string RfidRangingNodeOptions::validate() const {
  std::string problem = common.validate();
  if (problem.empty()) problem = fleet.validate();
  if (problem.empty()) problem = model.validate();
  return problem;
}

const std::vector<std::string>& RfidRangingNodeOptions::yamlKeys() {
  return rfidTable().keys();
}

RfidRangingNodeOptions RfidRangingNodeOptions::fromYaml(const YAML::Node& node,
                                                        std::vector<std::string>* messages) {
  return readNode(node, "rfid_ranging", rfidTable(), RfidModelOptions::yamlKeys(), messages,
                  [&](RfidRangingNodeOptions& o) { o.model = RfidModelOptions::fromYaml(node); });
}

RfidRangingNodeOptions RfidRangingNodeOptions::fromYamlFile(const std::string& path,
                                                            std::vector<std::string>* messages) {
  return fromFile<RfidRangingNodeOptions>(path, messages);
}

std::string UwbRangingNodeOptions::validate() const {
  std::string problem = common.validate();
  if (problem.empty()) problem = fleet.validate();
  if (!problem.empty()) return problem;
  if (!(flush_period > 0.0) || !std::isfinite(flush_period))
    return core::badValue("flush_period", flush_period, "finite and > 0");
  return ranging.validate();
}

const std::vector<std::string>& UwbRangingNodeOptions::yamlKeys() {
  return uwbTable().keys();
}

UwbRangingNodeOptions UwbRangingNodeOptions::fromYaml(const YAML::Node& node,
                                                      std::vector<std::string>* messages) {
  return readNode(node, "uwb_ranging", uwbTable(), UwbRangingOptions::yamlKeys(), messages,
                  [&](UwbRangingNodeOptions& o) { o.ranging = UwbRangingOptions::fromYaml(node); });
}

UwbRangingNodeOptions UwbRangingNodeOptions::fromYamlFile(const std::string& path,
                                                          std::vector<std::string>* messages) {
  return fromFile<UwbRangingNodeOptions>(path, messages);
}

}  // namespace sensors
}  // namespace picker_localisation
