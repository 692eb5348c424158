// Checking the keys of an options YAML map: unknown keys are reported with the closest known one, so a typo
// (`num_particle`) is named instead of silently ignored. ROS-free.
#pragma once

#include <yaml-cpp/yaml.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace picker_localisation {
namespace core {

// The known key closest to `key` by edit distance ("" when `known` is empty).
std::string closestKey(const std::string& key, const std::vector<std::string>& known);
// One message per key of the map `node` that is not in `known`: "<component>: unknown key 'x' (did you mean
// 'y'?)". A node that is not a map gives none.
std::vector<std::string> unknownKeys(const YAML::Node& node, const std::vector<std::string>& known,
                                     const std::string& component);

// The message of a validate() that refuses a value: "<key> = <value>: must be <rule>".
std::string badValue(const char* key, double value, const char* rule);

// The end of an Options::fromYaml(node, &unknown): throws std::runtime_error "<component>: <problem>" when
// o.validate() refuses a value, then appends one message per key of `node` not in `known` to *unknown (when
// given). Returns o.
template <class Options>
Options checkOptions(Options o, const YAML::Node& node, const std::vector<std::string>& known,
                     const std::string& component, std::vector<std::string>* unknown) {
  const std::string problem = o.validate();
  if (!problem.empty()) throw std::runtime_error(component + ": " + problem);
  if (unknown)
    for (auto& m : unknownKeys(node, known, component)) unknown->push_back(std::move(m));
  return o;
}

// Sets `value` from node[key] when present; a value of the wrong type throws std::runtime_error
// "<component>: key '<key>' has the wrong type".
template <typename T>
void readOption(const YAML::Node& node, const std::string& component, const char* key, T& value) {
  if (!node[key]) return;
  try {
    value = node[key].as<T>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(component + ": key '" + key + "' has the wrong type");
  }
}

}  // namespace core
}  // namespace picker_localisation
