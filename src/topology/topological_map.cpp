#include "picker_localisation/topology/topological_map.h"

#include <algorithm>
#include <cmath>
#include <list>
#include <mutex>
#include <queue>
#include <regex>
#include <set>
#include <sstream>

namespace picker_localisation {
namespace topology {

namespace {
// A map error is one log line: a part longer than this (a 2 MB token of a broken file) is cut.
std::string clipped(const std::string& text, std::size_t max = 160) {
  if (text.size() <= max) return text;
  return text.substr(0, max) + "... (" + std::to_string(text.size()) + " characters)";
}

std::string formatMapError(const std::string& file, const std::string& problem, const std::string& node,
                           const std::string& field) {
  std::ostringstream s;
  s << clipped(file) << ": " << clipped(problem, 400);
  if (!node.empty() || !field.empty()) {
    s << " (";
    if (!node.empty()) s << "node '" << clipped(node) << "'";
    if (!node.empty() && !field.empty()) s << ", ";
    if (!field.empty()) s << "field '" << clipped(field) << "'";
    s << ")";
  }
  return s.str();
}

// Static 2-D k-d tree over node positions (median split, built once).
class KdTree2 {
 public:
  void build(const std::vector<Eigen::Vector2d>& points) {
    points_ = points;
    order_.resize(points.size());
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<NodeIndex>(i);
    buildRange(0, order_.size(), 0);
  }

  NodeIndex nearest(const Eigen::Vector2d& p) const {
    NodeIndex best = kInvalidNode;
    double best_d2 = std::numeric_limits<double>::infinity();
    nearestRange(p, 0, order_.size(), 0, best, best_d2);
    return best;
  }

  void within(const Eigen::Vector2d& p, double r, std::vector<NodeIndex>& out) const {
    withinRange(p, r * r, r, 0, order_.size(), 0, out);
  }

 private:
  void buildRange(std::size_t lo, std::size_t hi, int axis) {
    if (hi - lo <= 1) return;
    std::size_t mid = lo + (hi - lo) / 2;
    std::nth_element(order_.begin() + lo, order_.begin() + mid, order_.begin() + hi,
                     [&](NodeIndex a, NodeIndex b) {
                       return points_[a][axis] < points_[b][axis] || (points_[a][axis] == points_[b][axis] && a < b);
                     });
    buildRange(lo, mid, 1 - axis);
    buildRange(mid + 1, hi, 1 - axis);
  }

  void nearestRange(const Eigen::Vector2d& p, std::size_t lo, std::size_t hi, int axis, NodeIndex& best,
                    double& best_d2) const {
    if (lo >= hi) return;
    std::size_t mid = lo + (hi - lo) / 2;
    NodeIndex n = order_[mid];
    double d2 = (points_[n] - p).squaredNorm();
    if (d2 < best_d2 || (d2 == best_d2 && n < best)) {
      best_d2 = d2;
      best = n;
    }
    double diff = p[axis] - points_[n][axis];
    if (diff < 0) {
      nearestRange(p, lo, mid, 1 - axis, best, best_d2);
      if (diff * diff <= best_d2) nearestRange(p, mid + 1, hi, 1 - axis, best, best_d2);
    } else {
      nearestRange(p, mid + 1, hi, 1 - axis, best, best_d2);
      if (diff * diff <= best_d2) nearestRange(p, lo, mid, 1 - axis, best, best_d2);
    }
  }

  void withinRange(const Eigen::Vector2d& p, double r2, double r, std::size_t lo, std::size_t hi, int axis,
                   std::vector<NodeIndex>& out) const {
    if (lo >= hi) return;
    std::size_t mid = lo + (hi - lo) / 2;
    NodeIndex n = order_[mid];
    if ((points_[n] - p).squaredNorm() <= r2) out.push_back(n);
    double diff = p[axis] - points_[n][axis];
    if (diff <= r) withinRange(p, r2, r, lo, mid, 1 - axis, out);
    if (diff >= -r) withinRange(p, r2, r, mid + 1, hi, 1 - axis, out);
  }

  std::vector<Eigen::Vector2d> points_;
  std::vector<NodeIndex> order_;
};
}  // namespace

MapError::MapError(const std::string& file, const std::string& problem, const std::string& node,
                   const std::string& field)
    : std::runtime_error(formatMapError(file, problem, node, field)),
      file_(file),
      problem_(problem),
      node_(node),
      field_(field) {}

struct TopologicalMap::Impl {
  KdTree2 kdtree;
  // Hop-distance rows cached per source node (bounded LRU so a 10k-node map cannot exhaust memory).
  static constexpr std::size_t kMaxCachedRows = 2048;
  mutable std::mutex mutex;
  mutable std::unordered_map<NodeIndex,
                               std::pair<std::shared_ptr<const std::vector<int>>, std::list<NodeIndex>::iterator>>
      hop_rows;
  mutable std::list<NodeIndex> lru;
};

TopologicalMap::TopologicalMap() : impl_(std::make_unique<Impl>()) {}
TopologicalMap::~TopologicalMap() = default;
TopologicalMap::TopologicalMap(TopologicalMap&&) noexcept = default;
TopologicalMap& TopologicalMap::operator=(TopologicalMap&&) noexcept = default;

TopologicalMap::TopologicalMap(const TopologicalMap& other)
    : name_(other.name_),
      metric_map_(other.metric_map_),
      source_(other.source_),
      datum_(other.datum_),
      nodes_(other.nodes_),
      edges_(other.edges_),
      index_(other.index_),
      successors_(other.successors_),
      neighbours_(other.neighbours_),
      num_undirected_edges_(other.num_undirected_edges_),
      lane_of_node_(other.lane_of_node_),
      lane_names_(other.lane_names_),
      lane_nodes_(other.lane_nodes_),
      component_(other.component_),
      num_components_(other.num_components_),
      bbox_(other.bbox_),
      impl_(std::make_unique<Impl>()) {
  impl_->kdtree = other.impl_->kdtree;
}

TopologicalMap& TopologicalMap::operator=(const TopologicalMap& other) {
  if (this != &other) {
    TopologicalMap copy(other);
    *this = std::move(copy);
  }
  return *this;
}

core::DatumConfig MapDatum::config() const {
  core::DatumConfig c;
  c.kind = core::DatumConfig::Kind::kLocalCartesian;
  c.latitude = latitude;
  c.longitude = longitude;
  c.altitude = altitude;
  return c;
}

void TopologicalMap::setDatum(std::optional<MapDatum> datum) {
  if (datum && (!std::isfinite(datum->latitude) || !std::isfinite(datum->longitude) ||
                !std::isfinite(datum->altitude) || std::abs(datum->latitude) > 90.0 ||
                std::abs(datum->longitude) > 180.0))
    throw MapError(source_, "datum latitude / longitude not finite or out of range", "", "meta.datum_latitude");
  datum_ = datum;
}

TopologicalMap TopologicalMap::build(std::string name, std::vector<Node> nodes, const std::vector<EdgeSpec>& edges,
                                     const std::string& source, std::string metric_map) {
  TopologicalMap map;
  map.name_ = std::move(name);
  map.metric_map_ = std::move(metric_map);
  map.source_ = source;
  if (nodes.empty()) throw MapError(source, "the map has no nodes", "", "nodes");
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Node& n = nodes[i];
    if (n.name.empty()) throw MapError(source, "node #" + std::to_string(i) + " has an empty name", "", "name");
    if (!n.position.allFinite()) throw MapError(source, "position is not finite", n.name, "pose.position");
    if (!map.index_.emplace(n.name, static_cast<NodeIndex>(i)).second)
      throw MapError(source, "duplicate node name", n.name, "name");
  }
  map.nodes_ = std::move(nodes);
  std::set<std::pair<NodeIndex, NodeIndex>> seen;
  for (const EdgeSpec& e : edges) {
    auto s = map.index_.find(e.source);
    if (s == map.index_.end()) throw MapError(source, "edge source is not a node", e.source, "edges");
    auto t = map.index_.find(e.target);
    if (t == map.index_.end())
      throw MapError(source, "edge '" + e.id + "' points to unknown node '" + e.target + "'", e.source,
                     "edges.node");
    if (!seen.emplace(s->second, t->second).second) continue;  // duplicate directed edge: keep the first
    Edge edge;
    edge.id = e.id;
    edge.source = s->second;
    edge.target = t->second;
    edge.action = e.action;
    edge.length = (map.nodes_[edge.source].position.head<2>() - map.nodes_[edge.target].position.head<2>()).norm();
    map.edges_.push_back(edge);
  }
  map.finalise();
  return map;
}

void TopologicalMap::finalise() {
  const std::size_t n = nodes_.size();
  successors_.assign(n, {});
  neighbours_.assign(n, {});
  for (const Edge& e : edges_) {
    if (e.source == e.target) continue;  // self loops carry no motion
    successors_[e.source].push_back(e.target);
    neighbours_[e.source].push_back(e.target);
    neighbours_[e.target].push_back(e.source);
  }
  num_undirected_edges_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    auto& nb = neighbours_[i];
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    num_undirected_edges_ += nb.size();
  }
  num_undirected_edges_ /= 2;

  // Components (BFS over the undirected graph).
  component_.assign(n, -1);
  num_components_ = 0;
  for (std::size_t s = 0; s < n; ++s) {
    if (component_[s] >= 0) continue;
    std::queue<NodeIndex> q;
    q.push(static_cast<NodeIndex>(s));
    component_[s] = static_cast<int>(num_components_);
    while (!q.empty()) {
      NodeIndex u = q.front();
      q.pop();
      for (NodeIndex v : neighbours_[u])
        if (component_[v] < 0) {
          component_[v] = static_cast<int>(num_components_);
          q.push(v);
        }
    }
    ++num_components_;
  }

  std::vector<Eigen::Vector2d> pts(n);
  bbox_.min_x = bbox_.min_y = std::numeric_limits<double>::infinity();
  bbox_.max_x = bbox_.max_y = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    pts[i] = nodes_[i].position.head<2>();
    bbox_.min_x = std::min(bbox_.min_x, pts[i].x());
    bbox_.min_y = std::min(bbox_.min_y, pts[i].y());
    bbox_.max_x = std::max(bbox_.max_x, pts[i].x());
    bbox_.max_y = std::max(bbox_.max_y, pts[i].y());
  }
  impl_->kdtree.build(pts);
  assignLanes();
}

void TopologicalMap::assignLanes() {
  const std::size_t n = nodes_.size();
  lane_of_node_.assign(n, kNoLane);
  lane_names_.clear();
  lane_nodes_.clear();

  auto addLane = [&](const std::string& lane_name) {
    lane_names_.push_back(lane_name);
    lane_nodes_.emplace_back();
    return static_cast<LaneIndex>(lane_names_.size() - 1);
  };

  // Rule 1: row_* tags.
  static const std::regex row_tag("^row_.+");
  std::unordered_map<std::string, LaneIndex> by_tag;
  for (std::size_t i = 0; i < n; ++i)
    for (const std::string& tag : nodes_[i].tags)
      if (std::regex_match(tag, row_tag)) {
        auto it = by_tag.find(tag);
        LaneIndex l = it == by_tag.end() ? (by_tag[tag] = addLane(tag)) : it->second;
        lane_of_node_[i] = l;
        lane_nodes_[static_cast<std::size_t>(l)].push_back(static_cast<NodeIndex>(i));
        break;
      }
  if (!lane_names_.empty()) return;

  // Components of a subgraph restricted to `member` nodes and `edge_ok` edges, in node order.
  auto componentsOf = [&](const std::vector<std::vector<NodeIndex>>& adjacency, std::size_t min_size) {
    std::vector<int> seen(n, 0);
    for (std::size_t s = 0; s < n; ++s) {
      if (seen[s] || adjacency[s].empty()) continue;
      std::vector<NodeIndex> comp;
      std::queue<NodeIndex> q;
      q.push(static_cast<NodeIndex>(s));
      seen[s] = 1;
      while (!q.empty()) {
        NodeIndex u = q.front();
        q.pop();
        comp.push_back(u);
        for (NodeIndex v : adjacency[u])
          if (!seen[v]) {
            seen[v] = 1;
            q.push(v);
          }
      }
      if (comp.size() < min_size) continue;
      std::sort(comp.begin(), comp.end());
      LaneIndex l = addLane("row_" + std::to_string(lane_names_.size()));
      for (NodeIndex u : comp) lane_of_node_[u] = l;
      lane_nodes_[static_cast<std::size_t>(l)] = comp;
    }
  };

  // Rule 2: row_traversal edges.
  std::vector<std::vector<NodeIndex>> row_adjacency(n);
  bool any_row_edge = false;
  for (const Edge& e : edges_)
    if (e.action == "row_traversal" && e.source != e.target) {
      row_adjacency[e.source].push_back(e.target);
      row_adjacency[e.target].push_back(e.source);
      any_row_edge = true;
    }
  if (any_row_edge) {
    componentsOf(row_adjacency, 2);
    return;
  }

  // Rule 3: chains of degree <= 2 nodes.
  std::vector<std::vector<NodeIndex>> chain_adjacency(n);
  for (std::size_t u = 0; u < n; ++u) {
    if (neighbours_[u].size() > 2) continue;
    for (NodeIndex v : neighbours_[u])
      if (neighbours_[v].size() <= 2) chain_adjacency[u].push_back(v);
  }
  componentsOf(chain_adjacency, kMinChainLaneNodes);
}

std::optional<NodeIndex> TopologicalMap::index(const std::string& name) const {
  auto it = index_.find(name);
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

bool TopologicalMap::connected(NodeIndex a, NodeIndex b) const {
  const auto& nb = neighbours_.at(a);
  return std::binary_search(nb.begin(), nb.end(), b);
}

double TopologicalMap::distance(NodeIndex a, NodeIndex b) const {
  return (nodes_.at(a).position.head<2>() - nodes_.at(b).position.head<2>()).norm();
}

std::optional<double> TopologicalMap::edgeLength(NodeIndex a, NodeIndex b) const {
  if (!connected(a, b)) return std::nullopt;
  return distance(a, b);
}

NodeIndex TopologicalMap::nearestNode(const Eigen::Vector2d& p) const {
  if (nodes_.empty()) return kInvalidNode;
  return impl_->kdtree.nearest(p);
}

double TopologicalMap::distanceToNearestNode(const Eigen::Vector2d& p) const {
  if (nodes_.empty()) return std::numeric_limits<double>::infinity();
  return (position2d(nearestNode(p)) - p).norm();
}

TopologicalMap::EdgePoint TopologicalMap::nearestEdgePoint(const Eigen::Vector2d& p) const {
  EdgePoint best;
  if (nodes_.empty()) return best;
  best.from = nearestNode(p);
  const Eigen::Vector2d a = position2d(best.from);
  double best_distance = std::numeric_limits<double>::infinity();
  for (NodeIndex n : neighbours(best.from)) {
    const Eigen::Vector2d ab = position2d(n) - a;
    const double length2 = ab.squaredNorm();
    const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
    const double d = (a + t * ab - p).squaredNorm();
    if (d < best_distance) {
      best_distance = d;
      best.to = n;
      best.fraction = t;
    }
  }
  return best;
}

std::vector<NodeIndex> TopologicalMap::nodesWithin(const Eigen::Vector2d& p, double radius) const {
  std::vector<NodeIndex> out;
  if (!(radius >= 0.0) || nodes_.empty()) return out;
  impl_->kdtree.within(p, radius, out);
  return out;
}

std::shared_ptr<const std::vector<int>> TopologicalMap::hopDistances(NodeIndex a) const {
  if (a >= nodes_.size()) throw std::out_of_range("hopDistances: node index out of range");
  std::lock_guard<std::mutex> lock(impl_->mutex);
  auto it = impl_->hop_rows.find(a);
  if (it != impl_->hop_rows.end()) {
    impl_->lru.splice(impl_->lru.begin(), impl_->lru, it->second.second);
    return it->second.first;
  }
  auto row = std::make_shared<std::vector<int>>(nodes_.size(), -1);
  std::queue<NodeIndex> q;
  (*row)[a] = 0;
  q.push(a);
  while (!q.empty()) {
    NodeIndex u = q.front();
    q.pop();
    for (NodeIndex v : neighbours_[u])
      if ((*row)[v] < 0) {
        (*row)[v] = (*row)[u] + 1;
        q.push(v);
      }
  }
  if (impl_->hop_rows.size() >= Impl::kMaxCachedRows) {  // evict the least recently used row
    impl_->hop_rows.erase(impl_->lru.back());
    impl_->lru.pop_back();
  }
  impl_->lru.push_front(a);
  impl_->hop_rows[a] = {row, impl_->lru.begin()};
  return row;
}

int TopologicalMap::hopDistance(NodeIndex a, NodeIndex b) const {
  if (b >= nodes_.size()) throw std::out_of_range("hopDistance: node index out of range");
  return (*hopDistances(a))[b];
}

std::vector<NodeIndex> TopologicalMap::shortestPath(NodeIndex a, NodeIndex b) const {
  const std::size_t n = nodes_.size();
  if (a >= n || b >= n) throw std::out_of_range("shortestPath: node index out of range");
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<NodeIndex> prev(n, kInvalidNode);
  using Item = std::pair<double, NodeIndex>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> pq;
  dist[a] = 0.0;
  pq.push({0.0, a});
  while (!pq.empty()) {
    auto [d, u] = pq.top();
    pq.pop();
    if (d > dist[u]) continue;
    if (u == b) break;
    for (NodeIndex v : neighbours_[u]) {
      double nd = d + distance(u, v);
      if (nd < dist[v]) {
        dist[v] = nd;
        prev[v] = u;
        pq.push({nd, v});
      }
    }
  }
  std::vector<NodeIndex> path;
  if (!std::isfinite(dist[b])) return path;
  for (NodeIndex v = b; v != kInvalidNode; v = prev[v]) path.push_back(v);
  std::reverse(path.begin(), path.end());
  return path;
}

std::vector<double> TopologicalMap::pathLengthsFrom(NodeIndex source) const {
  std::vector<double> dist(nodes_.size(), std::numeric_limits<double>::infinity());
  if (source >= nodes_.size()) return dist;
  using Item = std::pair<double, NodeIndex>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> pq;
  dist[source] = 0.0;
  pq.push({0.0, source});
  while (!pq.empty()) {
    const auto [d, u] = pq.top();
    pq.pop();
    if (d > dist[u]) continue;
    for (NodeIndex v : neighbours_[u]) {
      const double nd = d + distance(u, v);
      if (nd < dist[v]) {
        dist[v] = nd;
        pq.push({nd, v});
      }
    }
  }
  return dist;
}

double TopologicalMap::pathLength(NodeIndex a, NodeIndex b) const {
  std::vector<NodeIndex> path = shortestPath(a, b);
  if (path.empty()) return std::numeric_limits<double>::infinity();
  double len = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) len += distance(path[i - 1], path[i]);
  return len;
}

std::string TopologicalMap::laneNameOf(NodeIndex i) const {
  LaneIndex l = lane(i);
  return l == kNoLane ? std::string() : laneName(l);
}

std::map<LaneIndex, double> TopologicalMap::massPerLane(const std::vector<NodeIndex>& nodes,
                                                        const std::vector<double>& masses) const {
  std::map<LaneIndex, double> per_lane;
  for (std::size_t k = 0; k < nodes.size() && k < masses.size(); ++k) per_lane[lane(nodes[k])] += masses[k];
  return per_lane;
}

std::string MapChange::summary() const {
  std::ostringstream s;
  s << "+" << added << " -" << removed << " nodes, " << moved << " moved";
  if (edges_changed) s << ", edges changed";
  if (lanes_changed) s << ", lanes changed";
  if (datum_changed) s << ", datum changed";
  return s.str();
}

MapChange compareMaps(const TopologicalMap& before, const TopologicalMap& after) {
  MapChange c;
  c.old_to_new.resize(before.numNodes(), kInvalidNode);
  for (NodeIndex i = 0; i < before.numNodes(); ++i) {
    const Node& old_node = before.node(i);
    if (const auto same = after.index(old_node.name)) {
      c.old_to_new[i] = *same;
      if ((after.node(*same).position - old_node.position).norm() > 0.01) ++c.moved;
      if (before.laneNameOf(i) != after.laneNameOf(*same)) c.lanes_changed = true;
    } else {
      ++c.removed;
      c.old_to_new[i] = after.nearestNode(before.position2d(i));
    }
  }
  for (const Node& n : after.nodes())
    if (!before.index(n.name)) ++c.added;
  auto named = [](const TopologicalMap& m) {
    std::set<std::pair<std::string, std::string>> pairs;
    for (const Edge& e : m.edges()) pairs.emplace(m.node(e.source).name, m.node(e.target).name);
    return pairs;
  };
  c.edges_changed = named(before) != named(after);
  if (before.laneNames() != after.laneNames()) c.lanes_changed = true;
  const auto& da = before.datum();
  const auto& db = after.datum();
  c.datum_changed = da.has_value() != db.has_value() ||
                    (da && (da->latitude != db->latitude || da->longitude != db->longitude ||
                            da->altitude != db->altitude));
  return c;
}

}  // namespace topology
}  // namespace picker_localisation
