// Synthetic polytunnel maps of any size, for tests and benchmarks. ROS-free.
#pragma once

#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace topology {

// A block of parallel lanes joined by a headland at both ends:
//
//   H0 -- H1 -- H2 -- ...          (headland row at y = -headland_gap, one node per lane)
//   |     |     |
//   r0_0  r1_0  r2_0               (lane k runs along +y at x = k * lane_spacing)
//   |     |     |
//   ...   ...   ...
//   r0_m  r1_m  r2_m
//   |     |     |
//   T0 -- T1 -- T2 -- ...          (headland row at the far end)
//
// Lane nodes are tagged `row_<k>` so the lane rule's tag precedence applies; every edge is written in both
// directions (action `row_traversal` inside lanes, `move_base` on the headlands).
struct PolytunnelSpec {
  std::size_t lanes = 12;
  std::size_t nodes_per_lane = 10;
  double lane_spacing = 1.5;   // m between lane centre lines
  double node_spacing = 3.0;   // m between consecutive lane nodes
  double headland_gap = 3.0;   // m from the last lane node to the headland node
  Eigen::Vector2d origin{0.0, 0.0};
  std::string name = "synthetic_polytunnel";
};

TopologicalMap makePolytunnelMap(const PolytunnelSpec& spec);

// A spec with about `total_nodes` nodes (lanes x (nodes_per_lane + 2)), roughly square in node count.
PolytunnelSpec polytunnelSpecWithNodes(std::size_t total_nodes);

}  // namespace topology
}  // namespace picker_localisation
