#include "picker_localisation/dispatch/dispatcher_node_options.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "picker_localisation/core/option_table.h"
#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace dispatch {

namespace {
const char* kComponent = "dispatcher";

const core::OptionTable<DispatcherNodeOptions>& table() {
  using O = DispatcherNodeOptions;
  static const core::OptionTable<O> t =
      core::OptionTable<O>()
          .add("pickers_file", &O::pickers_file)
          .add("robots", &O::robots)
          .add("num_robots", &O::num_robots)
          .add("map_frame", &O::map_frame)
          .add("base_frame", &O::base_frame)
          .add("update_period", &O::update_period)
          .add("max_pose_age", &O::max_pose_age)
          .add("goal_topic", &O::goal_topic)
          .add("goal_pose_topic", &O::goal_pose_topic)
          .add("goal_node_topic", &O::goal_node_topic)
          .add("calls_topic", &O::calls_topic)
          .add("car_topic", &O::car_topic)
          .add("rfid_topic", &O::rfid_topic)
          .add("observations_topic", &O::observations_topic)
          .add("arrival_sensors", &O::arrival_sensors)
          .add("max_fix_distance", &O::max_fix_distance)
          .add("forward_fix", &O::forward_fix)
          .add("row_evidence_floor", &O::row_evidence_floor)
          .add("closed_calls_kept", &O::closed_calls_kept)
          .add("calls_log", &O::calls_log)
          .add("datum_file", &O::datum_file)
          .add("datum_source", &O::datum_source)
          .add("belief_topic", &O::fleet, &core::FleetTopicOptions::belief_topic)
          .add("registry_topic", &O::fleet, &core::FleetTopicOptions::registry_topic)
          .add("registry_publisher", &O::fleet, &core::FleetTopicOptions::registry_publisher)
          .add("map_file", &O::map_source, &core::CommonNodeOptions::map_file)
          .add("map_topic", &O::map_source, &core::CommonNodeOptions::map_topic)
          .add("map_timeout", &O::map_source, &core::CommonNodeOptions::map_timeout);
  return t;
}

}  // namespace

// ---- options
// ------------------------------------------------------------------------------------------------

std::vector<std::string> DispatcherNodeOptions::robotIds() const {
  if (!robots.empty()) return robots;
  std::vector<std::string> ids;
  for (int r = 1; r <= num_robots; ++r) ids.push_back("robot_" + std::to_string(r));
  return ids;
}

std::string DispatcherNodeOptions::baseFrame(const std::string& robot) const {
  std::string frame = base_frame;
  const auto at = frame.find("{robot}");
  if (at != std::string::npos) frame.replace(at, 7, robot);
  return frame;
}

std::string DispatcherNodeOptions::validate() const {
  if (!(update_period > 0.0) || !std::isfinite(update_period))
    return core::badValue("update_period", update_period, "> 0");
  if (!(max_pose_age >= 0.0)) return core::badValue("max_pose_age", max_pose_age, ">= 0");
  if (!(map_source.map_timeout >= 0.0)) return core::badValue("map_timeout", map_source.map_timeout, ">= 0");
  if (robots.empty() && num_robots < 1) return core::badValue("num_robots", num_robots, ">= 1");
  for (const std::string& r : robots)
    if (r.empty() || !std::isalpha(static_cast<unsigned char>(r[0])) ||
        !std::all_of(r.begin(), r.end(), [](unsigned char ch) { return std::isalnum(ch) || ch == '_'; }))
      return "robots: '" + r + "' is not a valid robot id (a ROS name: a letter, then letters, digits, _)";
  if (goal_topic.empty()) return "goal_topic: must not be empty";
  if (!(max_fix_distance > 0.0)) return core::badValue("max_fix_distance", max_fix_distance, "> 0");
  if (!(row_evidence_floor > 0.0 && row_evidence_floor <= 1.0))
    return core::badValue("row_evidence_floor", row_evidence_floor, "in (0, 1]");
  if (closed_calls_kept < 0) return core::badValue("closed_calls_kept", closed_calls_kept, ">= 0");
  if (datum_source != "auto" && datum_source != "file" && datum_source != "map")
    return "datum_source = " + datum_source + ": must be auto, file or map";
  return dispatcher.validate();
}

const std::vector<std::string>& DispatcherNodeOptions::yamlKeys() {
  return table().keys();
}

DispatcherNodeOptions DispatcherNodeOptions::fromYaml(const YAML::Node& node,
                                                      std::vector<std::string>* unknown) {
  DispatcherNodeOptions o;
  const std::string c = kComponent;
  table().read(node, c, o);
  // The dispatcher's own keys (config/dispatcher.yaml) sit in the same namespace.
  YAML::Node core_keys(YAML::NodeType::Map);
  if (node.IsMap())
    for (const auto& kv : node) {
      const std::string key = kv.first.as<std::string>();
      const auto& known = DispatcherOptions::yamlKeys();
      if (std::find(known.begin(), known.end(), key) != known.end()) core_keys[key] = kv.second;
    }
  o.dispatcher = DispatcherOptions::fromYaml(core_keys);
  std::vector<std::string> all = yamlKeys();
  for (const auto& k : DispatcherOptions::yamlKeys()) all.push_back(k);
  return core::checkOptions(o, node, all, c, unknown);
}

}  // namespace dispatch
}  // namespace picker_localisation
