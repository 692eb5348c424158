// Shared by the sensors_ranging gtests: lattice maps (nodes on a square lattice, with or without edges), the
// likelihood of an observation at a node, a two-picker registry and the Riseholme datum.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <algorithm>
#include <limits>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"
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

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// An observation's likelihood at node n (0 where it lists none).
inline double likelihoodAt(const picker_localisation::core::Observation& obs,
                           picker_localisation::topology::NodeIndex n) {
  auto it = std::find(obs.nodes.begin(), obs.nodes.end(), n);
  return it == obs.nodes.end() ? 0.0 : obs.likelihood[static_cast<std::size_t>(it - obs.nodes.begin())];
}

inline picker_localisation::topology::NodeIndex nodeAt(
    const picker_localisation::topology::TopologicalMap& map, double x, double y) {
  return map.nearestNode(Eigen::Vector2d(x, y));
}

inline picker_localisation::core::PickerRegistry twoPickers() {
  return picker_localisation::core::PickerRegistry::parse(
      "pickers:\n"
      "  - {id: picker_1, gnss_topic: /pickers/picker_1/fix, rfid_tags: [rfid_1], uwb_tag: uwb_1}\n"
      "  - {id: picker_2, gnss_topic: /pickers/picker_2/fix, rfid_tags: [rfid_2], uwb_tag: uwb_2}\n");
}

inline picker_localisation::core::DatumConfig riseholmeDatum(double heading_deg = 0.0) {
  picker_localisation::core::DatumConfig c;
  c.latitude = 53.268;
  c.longitude = -0.524;
  c.heading = heading_deg * M_PI / 180.0;
  return c;
}

}  // namespace ranging_test
