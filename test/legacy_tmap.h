// A legacy (2018 RASberry, MongoDB-dump) topological map written from the shipped tmap2 map, so the legacy
// reader is tested on a file the package may ship (the LCAS map is MIT; the 2018 legacy maps come without a
// licence).
//
// The legacy format is the tmap2's `nodes` list on its own: a YAML list of {meta, node} documents. What the
// 2018 maps do differently, and this copy does too: goal tolerances flat under `node` (no `properties`),
// every edge a `move_base` edge (so lanes come from the chain structure, not from `row_traversal` actions),
// and many edges one-way: each row edge of the source is kept only from the lower to the higher WayPoint
// number. The source has 216 directed row_traversal edges, all in both directions (config/maps/README.md), so
// the copy has 308 - 108 = 200 directed edges and still 154 undirected ones. Map and pointset are renamed
// `riseholme_legacy`.
#pragma once

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace picker_localisation {
namespace test {

inline constexpr std::size_t kLegacyNodes = 138, kLegacyDirectedEdges = 200, kLegacyUndirectedEdges = 154;

// WayPoint<N> -> N; -1 for any other name.
inline long wayPointNumber(const std::string& name) {
  const std::string prefix = "WayPoint";
  if (name.rfind(prefix, 0) != 0 || name.size() == prefix.size()) return -1;
  try {
    return std::stol(name.substr(prefix.size()));
  } catch (const std::exception&) {
    return -1;
  }
}

// Writes the legacy copy of `tmap2_path` to `out_path`.
inline void writeLegacyCopy(const std::string& tmap2_path, const std::string& out_path) {
  const YAML::Node root = YAML::LoadFile(tmap2_path);
  YAML::Node legacy(YAML::NodeType::Sequence);
  for (const YAML::Node& entry : root["nodes"]) {
    const YAML::Node body = entry["node"];
    const std::string name = body["name"].as<std::string>();
    YAML::Node meta;
    meta["map"] = "riseholme_legacy";
    meta["node"] = name;
    meta["pointset"] = "riseholme_legacy";
    YAML::Node node;
    node["name"] = name;
    node["map"] = "riseholme_legacy";
    node["pointset"] = "riseholme_legacy";
    node["pose"] = YAML::Clone(body["pose"]);
    node["xy_goal_tolerance"] = body["properties"]["xy_goal_tolerance"].as<double>();
    node["yaw_goal_tolerance"] = body["properties"]["yaw_goal_tolerance"].as<double>();
    YAML::Node edges(YAML::NodeType::Sequence);
    for (const YAML::Node& e : body["edges"]) {
      const std::string target = e["node"].as<std::string>();
      const bool row_edge = e["action"].as<std::string>() == "row_traversal";
      if (row_edge && wayPointNumber(name) > wayPointNumber(target)) continue;  // one-way: low -> high only
      YAML::Node edge;
      edge["action"] = "move_base";
      edge["edge_id"] = name + "_" + target;
      edge["node"] = target;
      edges.push_back(edge);
    }
    node["edges"] = edges;
    YAML::Node doc;
    doc["meta"] = meta;
    doc["node"] = node;
    legacy.push_back(doc);
  }
  std::ofstream out(out_path);
  out << legacy << "\n";
  if (!out) throw std::runtime_error("cannot write " + out_path);
}

// The legacy copy of the shipped map, written once per test process into a temporary folder removed at exit.
inline const std::string& legacyRiseholmePath() {
  struct Holder {
    std::filesystem::path dir;
    std::string file;
    Holder() {
      dir = std::filesystem::temp_directory_path() /
            ("picker_localisation_legacy_" + std::to_string(static_cast<long>(::getpid())));
      std::filesystem::create_directories(dir);
      file = (dir / "riseholme_legacy.tmap").string();
      writeLegacyCopy(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2", file);
    }
    ~Holder() {
      std::error_code ignored;
      std::filesystem::remove_all(dir, ignored);
    }
  };
  static const Holder holder;
  return holder.file;
}

}  // namespace test
}  // namespace picker_localisation
