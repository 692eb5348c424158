#include "picker_localisation/topology/synthetic_map.h"

#include <algorithm>
#include <cmath>

namespace picker_localisation {
namespace topology {

TopologicalMap makePolytunnelMap(const PolytunnelSpec& spec) {
  if (spec.lanes == 0 || spec.nodes_per_lane == 0)
    throw MapError(spec.name, "a polytunnel needs at least one lane with one node");
  std::vector<Node> nodes;
  std::vector<EdgeSpec> edges;
  nodes.reserve(spec.lanes * (spec.nodes_per_lane + 2));
  auto add = [&](const std::string& name, double x, double y, const std::string& tag) {
    Node n;
    n.name = name;
    n.position = Eigen::Vector3d(spec.origin.x() + x, spec.origin.y() + y, 0.0);
    if (!tag.empty()) n.tags.push_back(tag);
    nodes.push_back(std::move(n));
  };
  auto link = [&](const std::string& a, const std::string& b, const std::string& action) {
    edges.push_back({a + "_" + b, a, b, action});
    edges.push_back({b + "_" + a, b, a, action});
  };
  const double far_y = (static_cast<double>(spec.nodes_per_lane) - 1.0) * spec.node_spacing + spec.headland_gap;
  for (std::size_t k = 0; k < spec.lanes; ++k) {
    const double x = static_cast<double>(k) * spec.lane_spacing;
    const std::string row = "row_" + std::to_string(k);
    add("H" + std::to_string(k), x, -spec.headland_gap, "");
    add("T" + std::to_string(k), x, far_y, "");
    for (std::size_t j = 0; j < spec.nodes_per_lane; ++j)
      add("r" + std::to_string(k) + "_" + std::to_string(j), x, static_cast<double>(j) * spec.node_spacing, row);
    link("H" + std::to_string(k), "r" + std::to_string(k) + "_0", "row_traversal");
    for (std::size_t j = 1; j < spec.nodes_per_lane; ++j)
      link("r" + std::to_string(k) + "_" + std::to_string(j - 1), "r" + std::to_string(k) + "_" + std::to_string(j),
           "row_traversal");
    link("r" + std::to_string(k) + "_" + std::to_string(spec.nodes_per_lane - 1), "T" + std::to_string(k),
         "row_traversal");
    if (k > 0) {
      link("H" + std::to_string(k - 1), "H" + std::to_string(k), "move_base");
      link("T" + std::to_string(k - 1), "T" + std::to_string(k), "move_base");
    }
  }
  return TopologicalMap::build(spec.name, std::move(nodes), edges, spec.name, spec.name);
}

PolytunnelSpec polytunnelSpecWithNodes(std::size_t total_nodes) {
  PolytunnelSpec spec;
  // lanes * (per_lane + 2) ~= total with per_lane ~= lanes.
  double root = std::sqrt(static_cast<double>(std::max<std::size_t>(total_nodes, 9)));
  spec.lanes = static_cast<std::size_t>(std::max(1.0, std::round(root)));
  std::size_t per_lane_total = (total_nodes + spec.lanes - 1) / spec.lanes;
  spec.nodes_per_lane = std::max<std::size_t>(1, per_lane_total > 2 ? per_lane_total - 2 : 1);
  spec.name = "synthetic_polytunnel_" + std::to_string(total_nodes);
  return spec;
}

}  // namespace topology
}  // namespace picker_localisation
