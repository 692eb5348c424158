// Lattice maps for the sensors_ranging gtests: nodes on a square lattice, no edges.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/topology/topological_map.h"

namespace ranging_test {

// Nodes every `spacing` m over [-half, half]^2, named n_<i>_<j>.
inline std::shared_ptr<const picker_localisation::topology::TopologicalMap> latticeMap(double half, double spacing) {
  using picker_localisation::topology::Node;
  using picker_localisation::topology::TopologicalMap;
  std::vector<Node> nodes;
  const int n = static_cast<int>(std::lround(2.0 * half / spacing));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      Node node;
      node.name = "n_" + std::to_string(i) + "_" + std::to_string(j);
      node.position = Eigen::Vector3d(-half + i * spacing, -half + j * spacing, 0.0);
      nodes.push_back(node);
    }
  return std::make_shared<const TopologicalMap>(TopologicalMap::build("lattice", nodes, {}));
}

}  // namespace ranging_test
