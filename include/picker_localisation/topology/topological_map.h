// Topological map of a farm: named nodes with poses, directed edges as in the file, an undirected motion
// graph, lanes (rows) and the graph queries every other component needs. ROS-free.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"

namespace picker_localisation {
namespace topology {

using NodeIndex = std::uint32_t;
using LaneIndex = std::int32_t;
constexpr NodeIndex kInvalidNode = std::numeric_limits<NodeIndex>::max();
constexpr LaneIndex kNoLane = -1;  // headland, docks: nodes outside every lane

// Error in a map's content or file. what() is one line: "<file>: <what is wrong> (node '<n>', field '<f>')".
class MapError : public std::runtime_error {
 public:
  MapError(const std::string& file, const std::string& problem, const std::string& node = "",
           const std::string& field = "");
  const std::string& file() const { return file_; }
  const std::string& problem() const { return problem_; }
  const std::string& node() const { return node_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_, problem_, node_, field_;
};

struct Node {
  std::string name;
  Eigen::Vector3d position{0.0, 0.0, 0.0};              // map frame, m
  std::array<double, 4> orientation{0.0, 0.0, 0.0, 1.0};  // quaternion x, y, z, w
  std::vector<std::string> tags;                        // meta.tag of tmap2 files (e.g. row_00006)
};

// A directed edge as written in the file.
struct Edge {
  std::string id;
  NodeIndex source = kInvalidNode;
  NodeIndex target = kInvalidNode;
  std::string action;
  double length = 0.0;  // Euclidean distance between the endpoints in the xy-plane, m
};

// An edge given by node names, as read from a file, before the names are resolved.
struct EdgeSpec {
  std::string id;
  std::string source;
  std::string target;
  std::string action;
};

// Where the map's origin is on the Earth, when the map file says so (tmap2 meta.datum_latitude /
// meta.datum_longitude [/ meta.datum_altitude], as LCAS topological_navigation's add_datum stores it): the map
// frame is then the local east-north frame at that point.
struct MapDatum {
  double latitude = 0.0;   // deg WGS84
  double longitude = 0.0;  // deg WGS84
  double altitude = 0.0;   // m
  // As a core::GeodeticDatum: local_cartesian at that point, map x east (heading 0).
  core::DatumConfig config() const;
};

struct BoundingBox {
  double min_x = 0.0, min_y = 0.0, max_x = 0.0, max_y = 0.0;
};

// How lanes are assigned (the rule, in order of precedence):
//  1. Tags: a node with a tag matching `row_<anything>` belongs to the lane named by that tag.
//  2. Row-traversal edges: if no node is tagged and the map has edges whose action is `row_traversal`,
//     each connected component (>= 2 nodes) of the undirected row_traversal subgraph is one lane, named
//     `row_<k>` in order of its first node in the file.
//  3. Chains: otherwise, remove the junction nodes (undirected degree >= 3); each remaining connected
//     component of >= kMinChainLaneNodes nodes (a chain of degree <= 2 nodes) is one lane, named `row_<k>`.
// Every other node (headland, docks, junctions) has lane kNoLane.
constexpr std::size_t kMinChainLaneNodes = 3;

class TopologicalMap {
 public:
  TopologicalMap();
  ~TopologicalMap();
  TopologicalMap(const TopologicalMap&);
  TopologicalMap& operator=(const TopologicalMap&);
  TopologicalMap(TopologicalMap&&) noexcept;
  TopologicalMap& operator=(TopologicalMap&&) noexcept;

  // Builds a map. Throws MapError (file = source) on an empty node list, a duplicate node name, a non-finite
  // position or an edge whose source or target is not a node. Duplicate directed edges are kept once.
  static TopologicalMap build(std::string name, std::vector<Node> nodes, const std::vector<EdgeSpec>& edges,
                              const std::string& source = "<memory>", std::string metric_map = "");

  const std::string& name() const { return name_; }
  const std::string& metricMap() const { return metric_map_; }
  const std::string& source() const { return source_; }
  const std::optional<MapDatum>& datum() const { return datum_; }
  // Throws MapError (file = source(), field meta.datum_latitude) on a latitude / longitude that is not finite
  // or out of range, or a non-finite altitude; the map is unchanged then.
  void setDatum(std::optional<MapDatum> datum);

  std::size_t numNodes() const { return nodes_.size(); }
  const Node& node(NodeIndex i) const { return nodes_.at(i); }
  const std::vector<Node>& nodes() const { return nodes_; }
  std::optional<NodeIndex> index(const std::string& name) const;
  Eigen::Vector2d position2d(NodeIndex i) const { return nodes_[i].position.head<2>(); }

  // Directed edges in file order (duplicates dropped).
  const std::vector<Edge>& edges() const { return edges_; }
  std::size_t numDirectedEdges() const { return edges_.size(); }
  // Number of node pairs joined by at least one edge in either direction.
  std::size_t numUndirectedEdges() const { return num_undirected_edges_; }
  // Out-neighbours, as in the file.
  const std::vector<NodeIndex>& successors(NodeIndex i) const { return successors_.at(i); }
  // Neighbours in the undirected motion graph (pickers walk both ways); sorted, unique, without i.
  const std::vector<NodeIndex>& neighbours(NodeIndex i) const { return neighbours_.at(i); }
  // The motion graph a filter uses: successors when directed, neighbours otherwise.
  const std::vector<NodeIndex>& motionNeighbours(NodeIndex i, bool directed) const {
    return directed ? successors(i) : neighbours(i);
  }
  bool connected(NodeIndex a, NodeIndex b) const;  // adjacent in the undirected motion graph

  // Euclidean distance in the xy-plane between two nodes, m.
  double distance(NodeIndex a, NodeIndex b) const;
  // Length of the edge a-b (either direction), m; nullopt when a and b are not adjacent.
  std::optional<double> edgeLength(NodeIndex a, NodeIndex b) const;

  // Nearest node to a point in the xy-plane (k-d tree, O(log n)).
  NodeIndex nearestNode(const Eigen::Vector2d& p) const;
  // Distance (m, xy-plane) from p to that node; +inf for an empty map. How far off the map a point is.
  double distanceToNearestNode(const Eigen::Vector2d& p) const;
  // The point of the graph nearest p among the edges at the nearest node: p projected onto the closest of
  // those edges, `fraction` of the way from `from` (the nearest node) to `to`. A node without neighbours (or
  // an empty map: both invalid) gives to == kInvalidNode, fraction 0. Lets a quantity known per node be read
  // at a position between two nodes (by linear interpolation) instead of at the nearest node, which on a lane
  // with nodes 3 m apart can be 1.5 m from p.
  struct EdgePoint {
    NodeIndex from = kInvalidNode;
    NodeIndex to = kInvalidNode;
    double fraction = 0.0;  // in [0, 1]
  };
  EdgePoint nearestEdgePoint(const Eigen::Vector2d& p) const;
  // Nodes within radius (m) of p, in no particular order (k-d tree range search).
  std::vector<NodeIndex> nodesWithin(const Eigen::Vector2d& p, double radius) const;

  // Hops between a and b in the undirected motion graph (BFS; one row per source is cached, thread-safe);
  // -1 when unreachable.
  int hopDistance(NodeIndex a, NodeIndex b) const;
  // All hop distances from a (cached row, shared so it stays valid after eviction; -1 unreachable).
  std::shared_ptr<const std::vector<int>> hopDistances(NodeIndex a) const;
  // Shortest path length in metres through the undirected motion graph (Dijkstra); +inf when unreachable.
  double pathLength(NodeIndex a, NodeIndex b) const;
  // Shortest path lengths in metres from `source` to every node (Dijkstra; +inf unreachable, all +inf for an
  // index out of range).
  std::vector<double> pathLengthsFrom(NodeIndex source) const;
  // Shortest path as a node sequence from a to b (both included); empty when unreachable.
  std::vector<NodeIndex> shortestPath(NodeIndex a, NodeIndex b) const;

  // Lanes (see the rule above).
  LaneIndex lane(NodeIndex i) const { return lane_of_node_.at(i); }
  std::size_t numLanes() const { return lane_names_.size(); }
  const std::string& laneName(LaneIndex l) const { return lane_names_.at(static_cast<std::size_t>(l)); }
  const std::vector<std::string>& laneNames() const { return lane_names_; }
  const std::vector<NodeIndex>& laneNodes(LaneIndex l) const { return lane_nodes_.at(static_cast<std::size_t>(l)); }
  // Name of a node's lane, or "" when it has none.
  std::string laneNameOf(NodeIndex i) const;
  // A sparse belief's mass (masses[k] at nodes[k]) summed per lane; mass on nodes without a lane under
  // kNoLane.
  std::map<LaneIndex, double> massPerLane(const std::vector<NodeIndex>& nodes,
                                          const std::vector<double>& masses) const;

  // Connected components of the undirected motion graph.
  std::size_t numComponents() const { return num_components_; }
  int component(NodeIndex i) const { return component_.at(i); }

  BoundingBox boundingBox() const { return bbox_; }

 private:
  struct Impl;  // spatial index and caches
  void finalise();
  void assignLanes();

  std::string name_, metric_map_, source_;
  std::optional<MapDatum> datum_;
  std::vector<Node> nodes_;
  std::vector<Edge> edges_;
  std::unordered_map<std::string, NodeIndex> index_;
  std::vector<std::vector<NodeIndex>> successors_, neighbours_;
  std::size_t num_undirected_edges_ = 0;
  std::vector<LaneIndex> lane_of_node_;
  std::vector<std::string> lane_names_;
  std::vector<std::vector<NodeIndex>> lane_nodes_;
  std::vector<int> component_;
  std::size_t num_components_ = 0;
  BoundingBox bbox_;
  std::unique_ptr<Impl> impl_;
};

// How a new version of a map relates to the one it replaces (a map manager edited the map at run time).
struct MapChange {
  std::size_t added = 0, removed = 0;  // nodes by name
  std::size_t moved = 0;               // same name, position changed by more than 1 cm
  bool edges_changed = false;          // the set of (source name, target name) pairs differs
  bool datum_changed = false;          // meta.datum_* added, removed or changed
  bool lanes_changed = false;          // a kept node is in another lane (re-tagged) or the lane names differ
  // For every node of the old map, its node in the new one: the node of the same name, else the node nearest
  // to where it was (map frame), so what sat on a removed or renamed node lands where it was.
  std::vector<NodeIndex> old_to_new;
  bool identical() const {
    return added + removed + moved == 0 && !edges_changed && !datum_changed && !lanes_changed;
  }
  // "+N -M nodes, K moved" [", edges changed"] [", lanes changed"] [", datum changed"].
  std::string summary() const;
};
MapChange compareMaps(const TopologicalMap& before, const TopologicalMap& after);

}  // namespace topology
}  // namespace picker_localisation
