// A node's options as one table of keys: fromYaml() reads the keys in the table, yamlKeys() lists them and
// the docs test checks each appears in the node's page, so a key cannot be read without being listed, or
// listed without being read. ROS-free: the config test loads every node's table.
#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace core {

// A list of strings; one string ("[a, b]", "a b", "a,b", as `rosrun ... _name:=` may give it) is split.
inline void readStringList(const YAML::Node& node, const std::string& component, const char* key,
                           std::vector<std::string>& value) {
  if (!node[key]) return;
  if (node[key].IsScalar()) {
    std::string text = node[key].as<std::string>();
    for (char& c : text)
      if (c == '[' || c == ']' || c == ',' || c == '\'' || c == '"') c = ' ';
    std::istringstream in(text);
    value.clear();
    for (std::string item; in >> item;) value.push_back(item);
    return;
  }
  readOption(node, component, key, value);
}

template <class Options>
class OptionTable {
 public:
  // A field of Options.
  template <class T>
  OptionTable& add(const char* key, T Options::*field) {
    return addReader(key, [key, field](const YAML::Node& n, const std::string& c, Options& o) {
      read(n, c, key, o.*field);
    });
  }
  // A field of a part of Options (a shared struct such as the fleet topics).
  template <class Part, class T>
  OptionTable& add(const char* key, Part Options::*part, T Part::*field) {
    return addReader(key, [key, part, field](const YAML::Node& n, const std::string& c, Options& o) {
      read(n, c, key, (o.*part).*field);
    });
  }

  void read(const YAML::Node& node, const std::string& component, Options& o) const {
    if (!node || !node.IsMap()) return;
    for (const auto& r : readers_) r(node, component, o);
  }
  const std::vector<std::string>& keys() const { return keys_; }

 private:
  using Reader = std::function<void(const YAML::Node&, const std::string&, Options&)>;
  OptionTable& addReader(const char* key, Reader r) {
    keys_.push_back(key);
    readers_.push_back(std::move(r));
    return *this;
  }
  template <class T>
  static void read(const YAML::Node& n, const std::string& c, const char* key, T& value) {
    if constexpr (std::is_same_v<T, std::vector<std::string>>)
      readStringList(n, c, key, value);
    else
      readOption(n, c, key, value);
  }

  std::vector<std::string> keys_;
  std::vector<Reader> readers_;
};

// The keys of several lists, in order: what a node's unknown-key check accepts.
inline std::vector<std::string> joinKeys(std::initializer_list<std::vector<std::string>> lists) {
  std::vector<std::string> all;
  for (const auto& l : lists) all.insert(all.end(), l.begin(), l.end());
  return all;
}

}  // namespace core
}  // namespace picker_localisation
