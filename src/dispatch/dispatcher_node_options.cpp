#include "picker_localisation/dispatch/dispatcher_node_options.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace dispatch {

namespace {
const char* kComponent = "dispatcher";
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
  static const std::vector<std::string> keys{
      "pickers_file", "robots", "num_robots", "map_frame", "base_frame", "update_period", "max_pose_age",
      "goal_topic", "goal_pose_topic", "goal_node_topic", "calls_topic", "car_topic", "rfid_topic",
      "observations_topic", "arrival_sensors", "max_fix_distance", "forward_fix", "row_evidence_floor",
      "closed_calls_kept", "calls_log", "datum_file", "datum_source",
      // read by the shared helpers (map_source, fleet_topics), documented with them
      "map_file", "map_topic", "map_timeout", "belief_topic", "registry_topic", "registry_publisher"};
  return keys;
}

DispatcherNodeOptions DispatcherNodeOptions::fromYaml(const YAML::Node& node,
                                                      std::vector<std::string>* unknown) {
  DispatcherNodeOptions o;
  const std::string c = kComponent;
  core::readOption(node, c, "pickers_file", o.pickers_file);
  core::readOption(node, c, "robots", o.robots);
  core::readOption(node, c, "num_robots", o.num_robots);
  core::readOption(node, c, "map_frame", o.map_frame);
  core::readOption(node, c, "base_frame", o.base_frame);
  core::readOption(node, c, "update_period", o.update_period);
  core::readOption(node, c, "max_pose_age", o.max_pose_age);
  core::readOption(node, c, "goal_topic", o.goal_topic);
  core::readOption(node, c, "goal_pose_topic", o.goal_pose_topic);
  core::readOption(node, c, "goal_node_topic", o.goal_node_topic);
  core::readOption(node, c, "calls_topic", o.calls_topic);
  core::readOption(node, c, "car_topic", o.car_topic);
  core::readOption(node, c, "rfid_topic", o.rfid_topic);
  core::readOption(node, c, "observations_topic", o.observations_topic);
  core::readOption(node, c, "arrival_sensors", o.arrival_sensors);
  core::readOption(node, c, "max_fix_distance", o.max_fix_distance);
  core::readOption(node, c, "forward_fix", o.forward_fix);
  core::readOption(node, c, "row_evidence_floor", o.row_evidence_floor);
  core::readOption(node, c, "closed_calls_kept", o.closed_calls_kept);
  core::readOption(node, c, "calls_log", o.calls_log);
  core::readOption(node, c, "datum_file", o.datum_file);
  core::readOption(node, c, "datum_source", o.datum_source);
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
