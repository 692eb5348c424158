// Lane geometry derived from any topological map's generic lane API: the order of the nodes along each lane,
// its two ends, which end is on the "entry side" of the farm, and which lane is adjacent to which. Pickers'
// tours and the robots' patrol are built from it. ROS-free.
//
// The rule (works on any map with lanes; a map without lanes yields an empty layout):
//  1. Order inside a lane: take the subgraph induced by the lane's nodes (undirected motion graph). If it
//     is a simple chain (every node degree <= 2, exactly two degree-1 ends, connected), the chain order is
//     the lane order. Otherwise (branches, gaps) the nodes are sorted by their projection on the lane's
//     principal axis (largest-eigenvalue eigenvector of the covariance of the node positions); a single-node
//     lane is its own both ends. The lane's two ends are the first and last node of that order.
//  2. Farm axis: the principal axes of all lanes with >= 2 nodes, sign-aligned to the first one and
//     weighted by lane length, are averaged into one unit "along" direction a; the "across" direction is a
//     rotated by +90 deg. Lanes are oriented so that their first node has the smaller projection on a: the
//     first node is the lane's entry end (the paper's "left side"), the last node its far end.
//  3. Adjacent lanes: lanes are sorted by the projection of their centroid on the across direction (ties
//     broken by the projection on a, then by lane index). The lane adjacent to lane k in the walking order is
//     the next one in that sorted list; the last lane's successor is the first (pickers start again from the
//     far side).
#pragma once

#include "picker_localisation/topology/topological_map.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace picker_localisation {
namespace sim {

struct LaneInfo {
  topology::LaneIndex lane = topology::kNoLane;
  std::vector<topology::NodeIndex> nodes;  // ordered from the entry end to the far end
  topology::NodeIndex entry_end() const { return nodes.front(); }
  topology::NodeIndex far_end() const { return nodes.back(); }
  Eigen::Vector2d centroid{0.0, 0.0};
  bool was_chain = true;  // false when the order came from the principal-axis fallback
};

class LaneLayout {
 public:
  explicit LaneLayout(const topology::TopologicalMap& map);

  bool empty() const { return lanes_.empty(); }
  // Lanes in adjacency order (across the farm), each oriented entry end first.
  const std::vector<LaneInfo>& lanes() const { return lanes_; }
  // Position of a map lane in lanes(); -1 when the lane has no info (kNoLane or unknown).
  int orderOf(topology::LaneIndex lane) const;
  const Eigen::Vector2d& alongAxis() const { return along_; }
  const Eigen::Vector2d& acrossAxis() const { return across_; }
  // Estimated centre-line spacing between adjacent lanes (median of the across-axis gaps of consecutive
  // lanes' centroids), m; 1.5 m when the map has fewer than two lanes.
  double laneSpacing() const { return lane_spacing_; }

 private:
  std::vector<LaneInfo> lanes_;
  std::vector<int> order_of_lane_;
  Eigen::Vector2d along_{1.0, 0.0}, across_{0.0, 1.0};
  double lane_spacing_ = 1.5;
};

// Which lanes a picker's tour walks and how:
//  serpentine    every lane in turn, alternating direction (the paper's walk, Sec. VI);
//  skip_one      every other lane (lanes 0, 2, 4 ... of the order from the start lane), alternating
//                direction: a picker whose neighbour works the lanes between;
//  out_and_back  every lane in turn, walked to its far end and back by the same lane to its entry end.
enum class LaneOrder { kSerpentine, kSkipOne, kOutAndBack };
LaneOrder parseLaneOrder(const std::string& name);  // throws std::invalid_argument naming the choices
const char* toString(LaneOrder order);

// A closed walking tour over the map as a node sequence where consecutive nodes are adjacent in the motion
// graph (the tour returns from its last node to its first through the graph as well).
//  - Map with lanes: the serpentine of the paper (Sec. VI). Starting with lanes()[start], the picker walks
//    each lane end to end, alternating direction: lanes at even positions (counted from lane 0 of the order)
//    are walked entry end -> far end, odd positions far end -> entry end, so every lane is always walked in
//    the same direction. Consecutive lanes are joined by the shortest path between the end just reached and
//    the next lane's starting end (through the headland). After the last lane the tour continues with lane 0.
//    A lane reachable through one end only (a dead end) is entered and left through that end.
//  - Map without lanes: the shortest paths through `fallback_waypoints` (e.g. random nodes of the component).
// Unreachable transitions are skipped (the next reachable lane is used); throws std::invalid_argument when
// the tour would have fewer than two nodes.
std::vector<topology::NodeIndex> buildLaneTour(
    const topology::TopologicalMap& map, const LaneLayout& layout, std::size_t start_lane,
    const std::vector<topology::NodeIndex>& fallback_waypoints = {},
    LaneOrder order = LaneOrder::kSerpentine);

}  // namespace sim
}  // namespace picker_localisation
