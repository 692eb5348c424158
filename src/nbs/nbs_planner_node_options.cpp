#include "picker_localisation/nbs/nbs_planner_node_options.h"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "picker_localisation/core/option_table.h"
#include "picker_localisation/core/yaml_file.h"

namespace picker_localisation {
namespace nbs {

namespace {

const char* kComponent = "nbs_planner";

const core::OptionTable<NbsPlannerNodeOptions>& table() {
  using O = NbsPlannerNodeOptions;
  using F = core::FleetTopicOptions;
  static const core::OptionTable<O> t = core::OptionTable<O>()
                                            .add("pickers_file", &O::fleet, &F::pickers_file)
                                            .add("robot_id", &O::robot_id)
                                            .add("base_frame", &O::base_frame)
                                            .add("planning_period", &O::planning_period)
                                            .add("claim_timeout", &O::claim_timeout)
                                            .add("max_pose_age", &O::max_pose_age)
                                            .add("battery_level", &O::battery_level)
                                            .add("use_what_if", &O::use_what_if)
                                            .add("what_if_seed", &O::what_if_seed)
                                            .add("fleet", &O::fleet_robots)
                                            .add("num_robots", &O::num_robots)
                                            .add("battery_topic", &O::battery_topic)
                                            .add("goal_pose_topic", &O::goal_pose_topic)
                                            .add("call_goal_topic", &O::call_goal_topic)
                                            .add("call_status_topic", &O::call_status_topic)
                                            .add("belief_topic", &O::fleet, &F::belief_topic)
                                            .add("registry_topic", &O::fleet, &F::registry_topic)
                                            .add("registry_publisher", &O::fleet, &F::registry_publisher);
  return t;
}

}  // namespace

std::string NbsPlannerNodeOptions::robotId(const std::string& node_namespace) const {
  if (!robot_id.empty()) return robot_id;
  std::string ns = node_namespace;
  while (!ns.empty() && ns.front() == '/') ns.erase(ns.begin());
  return ns.empty() ? "robot_1" : ns;
}

std::string NbsPlannerNodeOptions::baseFrame(const std::string& robot) const {
  std::string frame = base_frame;
  const auto at = frame.find("{robot_id}");
  if (at != std::string::npos) frame.replace(at, 10, robot);
  return frame;
}

std::vector<std::string> NbsPlannerNodeOptions::robotIds() const {
  if (!fleet_robots.empty()) return fleet_robots;
  std::vector<std::string> ids;
  for (int r = 1; r <= num_robots; ++r) ids.push_back("robot_" + std::to_string(r));
  return ids;
}

std::string NbsPlannerNodeOptions::validate() const {
  std::string problem = common.validate();
  if (problem.empty()) problem = fleet.validate();
  if (!problem.empty()) return problem;
  if (!(planning_period > 0.0) || !std::isfinite(planning_period))
    return core::badValue("planning_period", planning_period, "finite and > 0");
  if (!(claim_timeout > 0.0)) return core::badValue("claim_timeout", claim_timeout, "> 0");
  if (!(max_pose_age >= 0.0)) return core::badValue("max_pose_age", max_pose_age, ">= 0 (0: any age)");
  if (!(battery_level >= 0.0 && battery_level <= 1.0))
    return core::badValue("battery_level", battery_level, "in [0, 1]");
  if (fleet_robots.empty() && num_robots < 1) return core::badValue("num_robots", num_robots, ">= 1");
  return planner.validate();
}

const std::vector<std::string>& NbsPlannerNodeOptions::yamlKeys() {
  return table().keys();
}

NbsPlannerNodeOptions NbsPlannerNodeOptions::fromYaml(const YAML::Node& node,
                                                      std::vector<std::string>* messages) {
  NbsPlannerNodeOptions o;
  o.common = core::CommonNodeOptions::fromYaml(node, kComponent, messages, o.common);
  table().read(node, kComponent, o);
  o.planner = PlannerConfig::fromYaml(node);
  // The planner's check over the node's keys too: a typo is named with the closest key of either.
  if (messages)
    for (auto& m : PlannerConfig::unknownKeys(
             node, core::joinKeys({yamlKeys(), core::CommonNodeOptions::acceptedKeys()})))
      messages->push_back(std::move(m));
  const std::string problem = o.validate();
  if (!problem.empty()) throw std::runtime_error(std::string(kComponent) + ": " + problem);
  return o;
}

NbsPlannerNodeOptions NbsPlannerNodeOptions::fromYamlFile(const std::string& path,
                                                          std::vector<std::string>* messages) {
  return core::parseYamlFile(path, [&](const YAML::Node& root) { return fromYaml(root, messages); });
}

}  // namespace nbs
}  // namespace picker_localisation
