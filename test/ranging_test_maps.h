// Lattice maps for the sensors_ranging gtests: nodes on a square lattice, with or without edges.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/topology/topological_map.h"

namespace ranging_test {

// Nodes every `spacing` m over [-half, half]^2, named n_<i>_<j>; `connected`: edges both ways between
// 4-neighbours.
inline std::shared_ptr<const picker_localisation::topology::TopologicalMap> latticeMap(
    double half, double spacing, bool connected = false) {
  using picker_localisation::topology::EdgeSpec;
  using picker_localisation::topology::Node;
  using picker_localisation::topology::TopologicalMap;
  std::vector<Node> nodes;
  std::vector<EdgeSpec> edges;
  const int n = static_cast<int>(std::lround(2.0 * half / spacing));
  auto name = [](int i, int j) { return "n_" + std::to_string(i) + "_" + std::to_string(j); };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      Node node;
      node.name = name(i, j);
      node.position = Eigen::Vector3d(-half + i * spacing, -half + j * spacing, 0.0);
      nodes.push_back(node);
      if (!connected) continue;
      if (i > 0) {
        edges.push_back({"", name(i, j), name(i - 1, j), "move_base"});
        edges.push_back({"", name(i - 1, j), name(i, j), "move_base"});
      }
      if (j > 0) {
        edges.push_back({"", name(i, j), name(i, j - 1), "move_base"});
        edges.push_back({"", name(i, j - 1), name(i, j), "move_base"});
      }
    }
  return std::make_shared<const TopologicalMap>(TopologicalMap::build("lattice", nodes, edges));
}

}  // namespace ranging_test
