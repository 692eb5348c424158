// What a map manager does to a tmap2 document while the robot runs (the map-update rostests): rename a node,
// remove one. YAML documents as loaded from a tmap2 file (nodes[].node.{name, edges[].node}, nodes[].meta.node).
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

namespace tmap_edits {

// Node `from` renamed `to`: its entry and every edge into it.
inline void renameNode(YAML::Node& doc, const std::string& from, const std::string& to) {
  for (YAML::Node n : doc["nodes"]) {
    if (n["node"]["name"].as<std::string>() == from) {
      n["node"]["name"] = to;
      n["meta"]["node"] = to;
    }
    for (YAML::Node e : n["node"]["edges"])
      if (e["node"].as<std::string>() == from) e["node"] = to;
  }
}

// Node `name` removed with every edge into it.
inline void removeNode(YAML::Node& doc, const std::string& name) {
  YAML::Node kept(YAML::NodeType::Sequence);
  for (YAML::Node n : doc["nodes"]) {
    if (n["node"]["name"].as<std::string>() == name) continue;
    YAML::Node edges(YAML::NodeType::Sequence);
    for (const YAML::Node& e : n["node"]["edges"])
      if (e["node"].as<std::string>() != name) edges.push_back(e);
    n["node"]["edges"] = edges;
    kept.push_back(n);
  }
  doc["nodes"] = kept;
}

}  // namespace tmap_edits
