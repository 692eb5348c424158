#include "picker_localisation/core/node_options.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <stdexcept>

#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace core {

const std::vector<std::string>& CommonNodeOptions::yamlKeys() {
  static const std::vector<std::string> keys{"map_frame",  "observations_topic", "max_future_stamp",
                                             "tf_timeout", "ordering_latency",   "map_file",
                                             "map_topic",  "map_timeout"};
  return keys;
}

const std::vector<std::pair<std::string, std::string>>& CommonNodeOptions::deprecatedKeys() {
  static const std::vector<std::pair<std::string, std::string>> keys{
      {"frame_id", "map_frame"}, {"fixed_frame", "map_frame"}, {"observation_topic", "observations_topic"}};
  return keys;
}

std::vector<std::string> CommonNodeOptions::acceptedKeys() {
  std::vector<std::string> keys = yamlKeys();
  for (const auto& [old_name, name] : deprecatedKeys()) keys.push_back(old_name);
  return keys;
}

std::string CommonNodeOptions::validate() const {
  if (map_frame.empty()) return "map_frame: must not be empty";
  if (!(max_future_stamp >= 0.0)) return badValue("max_future_stamp", max_future_stamp, ">= 0");
  if (!(tf_timeout >= 0.0) || !std::isfinite(tf_timeout)) return badValue("tf_timeout", tf_timeout, ">= 0");
  if (!std::isfinite(ordering_latency)) return badValue("ordering_latency", ordering_latency, "finite");
  if (!(map_timeout >= 0.0)) return badValue("map_timeout", map_timeout, ">= 0");
  return "";
}

CommonNodeOptions CommonNodeOptions::fromYaml(const YAML::Node& node, const std::string& component,
                                              std::vector<std::string>* warnings, CommonNodeOptions o) {
  if (!node || !node.IsMap()) return o;
  // Old names first, so the new name wins when both are set.
  for (const auto& [old_name, name] : deprecatedKeys()) {
    if (!node[old_name]) continue;
    if (warnings)
      warnings->push_back(component + ": parameter '" + old_name + "' is deprecated, use '" + name + "'" +
                          (node[name] ? " (both are set: '" + name + "' is used)" : ""));
    std::string& field = name == "map_frame" ? o.map_frame : o.observations_topic;
    readOption(node, component, old_name.c_str(), field);
  }
  readOption(node, component, "map_frame", o.map_frame);
  readOption(node, component, "observations_topic", o.observations_topic);
  readOption(node, component, "max_future_stamp", o.max_future_stamp);
  readOption(node, component, "tf_timeout", o.tf_timeout);
  readOption(node, component, "ordering_latency", o.ordering_latency);
  readOption(node, component, "map_file", o.map_file);
  readOption(node, component, "map_topic", o.map_topic);
  readOption(node, component, "map_timeout", o.map_timeout);
  const std::string problem = o.validate();
  if (!problem.empty()) throw std::runtime_error(component + ": " + problem);
  return o;
}

std::string FleetTopicOptions::validate() const {
  if (on_demand_topics_above < 0) return badValue("on_demand_topics_above", on_demand_topics_above, ">= 0");
  if (!(demand_poll_period >= 0.2) || !std::isfinite(demand_poll_period))
    return badValue("demand_poll_period", demand_poll_period, "finite and >= 0.2");
  if (!(silent_warn_after >= 0.0)) return badValue("silent_warn_after", silent_warn_after, ">= 0 (0: never)");
  return "";
}

}  // namespace core
}  // namespace picker_localisation
