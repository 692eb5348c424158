// Reading a configuration file: one error line that names the file, whatever went wrong. ROS-free.
#pragma once

#include <yaml-cpp/yaml.h>

#include <stdexcept>
#include <string>

namespace picker_localisation {
namespace core {

// Loads the YAML file at `path` and returns parse(root). A YAML error while loading, or a std::runtime_error
// thrown by `parse`, comes back as std::runtime_error("<path>: <what>").
template <class Parse>
auto parseYamlFile(const std::string& path, Parse&& parse) -> decltype(parse(YAML::Node())) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  try {
    return parse(root);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace core
}  // namespace picker_localisation
