#include "picker_localisation/sim/lane_layout.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

namespace picker_localisation {
namespace sim {

using topology::LaneIndex;
using topology::NodeIndex;

namespace {

// Principal axis (unit) of a set of points; (1, 0) when degenerate.
Eigen::Vector2d principalAxis(const std::vector<Eigen::Vector2d>& pts, const Eigen::Vector2d& mean) {
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
  if (cov.trace() < 1e-12) return {1.0, 0.0};
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(cov);
  Eigen::Vector2d v = es.eigenvectors().col(1);
  return v.normalized();
}

// Chain order of the lane's induced subgraph, or empty when it is not a simple connected chain.
std::vector<NodeIndex> chainOrder(const topology::TopologicalMap& map, const std::vector<NodeIndex>& nodes) {
  if (nodes.size() < 2) return nodes;
  std::unordered_set<NodeIndex> in(nodes.begin(), nodes.end());
  auto laneNeighbours = [&](NodeIndex n) {
    std::vector<NodeIndex> out;
    for (NodeIndex m : map.neighbours(n))
      if (in.count(m)) out.push_back(m);
    return out;
  };
  std::vector<NodeIndex> ends;
  for (NodeIndex n : nodes) {
    const std::size_t d = laneNeighbours(n).size();
    if (d == 0 || d > 2) return {};
    if (d == 1) ends.push_back(n);
  }
  if (ends.size() != 2) return {};
  std::vector<NodeIndex> order{std::min(ends[0], ends[1])};
  NodeIndex prev = topology::kInvalidNode;
  while (order.size() < nodes.size()) {
    NodeIndex next = topology::kInvalidNode;
    for (NodeIndex m : laneNeighbours(order.back()))
      if (m != prev) next = m;
    if (next == topology::kInvalidNode) return {};
    prev = order.back();
    order.push_back(next);
  }
  return order;
}

}  // namespace

LaneLayout::LaneLayout(const topology::TopologicalMap& map) {
  order_of_lane_.assign(map.numLanes(), -1);
  std::vector<LaneInfo> infos;
  std::vector<Eigen::Vector2d> axes;
  std::vector<double> lengths;
  for (std::size_t l = 0; l < map.numLanes(); ++l) {
    const auto& nodes = map.laneNodes(static_cast<LaneIndex>(l));
    if (nodes.empty()) continue;
    LaneInfo info;
    info.lane = static_cast<LaneIndex>(l);
    std::vector<Eigen::Vector2d> pts;
    for (NodeIndex n : nodes) pts.push_back(map.position2d(n));
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : pts) mean += p;
    mean /= static_cast<double>(pts.size());
    info.centroid = mean;
    const Eigen::Vector2d axis = principalAxis(pts, mean);
    info.nodes = chainOrder(map, nodes);
    if (info.nodes.empty()) {
      info.was_chain = false;
      info.nodes = nodes;
      std::stable_sort(info.nodes.begin(), info.nodes.end(), [&](NodeIndex a, NodeIndex b) {
        return axis.dot(map.position2d(a)) < axis.dot(map.position2d(b));
      });
    }
    const double length = (map.position2d(info.nodes.back()) - map.position2d(info.nodes.front())).norm();
    infos.push_back(std::move(info));
    axes.push_back(axis);
    lengths.push_back(length);
  }
  if (infos.empty()) return;

  // Farm axis: length-weighted mean of the sign-aligned lane axes.
  Eigen::Vector2d along = Eigen::Vector2d::Zero();
  const Eigen::Vector2d ref = axes.front();
  for (std::size_t i = 0; i < axes.size(); ++i) {
    if (infos[i].nodes.size() < 2) continue;
    const Eigen::Vector2d a = axes[i].dot(ref) < 0.0 ? Eigen::Vector2d(-axes[i]) : axes[i];
    along += std::max(lengths[i], 1e-3) * a;
  }
  if (along.norm() < 1e-9) along = Eigen::Vector2d(1.0, 0.0);
  along_ = along.normalized();
  across_ = Eigen::Vector2d(-along_.y(), along_.x());

  for (auto& info : infos) {
    const double first = along_.dot(map.position2d(info.nodes.front()));
    const double last = along_.dot(map.position2d(info.nodes.back()));
    if (last < first) std::reverse(info.nodes.begin(), info.nodes.end());
  }
  std::stable_sort(infos.begin(), infos.end(), [&](const LaneInfo& a, const LaneInfo& b) {
    const double ca = across_.dot(a.centroid), cb = across_.dot(b.centroid);
    if (std::abs(ca - cb) > 1e-6) return ca < cb;
    const double aa = along_.dot(a.centroid), ab = along_.dot(b.centroid);
    if (std::abs(aa - ab) > 1e-6) return aa < ab;
    return a.lane < b.lane;
  });
  lanes_ = std::move(infos);
  for (std::size_t i = 0; i < lanes_.size(); ++i)
    order_of_lane_[static_cast<std::size_t>(lanes_[i].lane)] = int(i);

  std::vector<double> gaps;
  for (std::size_t i = 1; i < lanes_.size(); ++i)
    gaps.push_back(std::abs(across_.dot(lanes_[i].centroid - lanes_[i - 1].centroid)));
  if (!gaps.empty()) {
    std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
    const double median = gaps[gaps.size() / 2];
    if (median > 0.1) lane_spacing_ = median;
  }
}

int LaneLayout::orderOf(LaneIndex lane) const {
  if (lane < 0 || static_cast<std::size_t>(lane) >= order_of_lane_.size()) return -1;
  return order_of_lane_[static_cast<std::size_t>(lane)];
}

namespace {
// Appends the shortest path from tour.back() to `to` (without repeating tour.back()); false if unreachable.
bool appendPath(const topology::TopologicalMap& map, std::vector<NodeIndex>& tour, NodeIndex to) {
  if (tour.empty()) {
    tour.push_back(to);
    return true;
  }
  if (tour.back() == to) return true;
  const auto path = map.shortestPath(tour.back(), to);
  if (path.empty()) return false;
  tour.insert(tour.end(), path.begin() + 1, path.end());
  return true;
}
}  // namespace

LaneOrder parseLaneOrder(const std::string& name) {
  if (name == "serpentine") return LaneOrder::kSerpentine;
  if (name == "skip_one") return LaneOrder::kSkipOne;
  if (name == "out_and_back") return LaneOrder::kOutAndBack;
  throw std::invalid_argument("lane_order '" + name + "': must be serpentine, skip_one or out_and_back");
}

const char* toString(LaneOrder order) {
  switch (order) {
    case LaneOrder::kSkipOne:
      return "skip_one";
    case LaneOrder::kOutAndBack:
      return "out_and_back";
    case LaneOrder::kSerpentine:
      break;
  }
  return "serpentine";
}

std::vector<NodeIndex> buildLaneTour(const topology::TopologicalMap& map, const LaneLayout& layout,
                                     std::size_t start_lane, const std::vector<NodeIndex>& fallback_waypoints,
                                     LaneOrder order) {
  std::vector<NodeIndex> tour;
  if (!layout.empty()) {
    const auto& lanes = layout.lanes();
    const std::size_t L = lanes.size();
    start_lane %= L;
    const std::size_t stride = order == LaneOrder::kSkipOne && L > 1 ? 2 : 1;
    for (std::size_t k = 0; k * stride < L; ++k) {
      const std::size_t pos = (start_lane + k * stride) % L;
      std::vector<NodeIndex> nodes = lanes[pos].nodes;
      if (order == LaneOrder::kOutAndBack) {
        nodes.insert(nodes.end(), lanes[pos].nodes.rbegin() + 1, lanes[pos].nodes.rend());
      } else if ((stride == 1 ? pos : k) % 2 == 1) {
        std::reverse(nodes.begin(), nodes.end());
      }
      // A lane not reachable from the tour so far is skipped; within a lane, consecutive nodes are joined by
      // shortest paths (they are adjacent on a chain lane).
      if (!tour.empty() && map.shortestPath(tour.back(), nodes.front()).empty()) continue;
      for (NodeIndex n : nodes) appendPath(map, tour, n);
    }
    // Close the tour: back to its first node.
    if (tour.size() >= 2 && tour.back() != tour.front()) {
      std::vector<NodeIndex> back = map.shortestPath(tour.back(), tour.front());
      if (back.size() > 2) tour.insert(tour.end(), back.begin() + 1, back.end() - 1);
    } else if (tour.size() >= 2 && tour.back() == tour.front()) {
      tour.pop_back();
    }
  } else {
    for (NodeIndex w : fallback_waypoints) {
      if (!tour.empty() && map.shortestPath(tour.back(), w).empty()) continue;
      appendPath(map, tour, w);
    }
    if (tour.size() >= 2) {
      std::vector<NodeIndex> back = map.shortestPath(tour.back(), tour.front());
      if (tour.back() == tour.front())
        tour.pop_back();
      else if (back.size() > 2)
        tour.insert(tour.end(), back.begin() + 1, back.end() - 1);
    }
  }
  // A single-lane single-node tour: walk to a neighbour and back.
  if (tour.size() == 1 && !map.neighbours(tour.front()).empty())
    tour.push_back(map.neighbours(tour.front()).front());
  if (tour.size() < 2)
    throw std::invalid_argument(
        "buildLaneTour: the map cannot host a walking tour (fewer than two connected nodes)");
  return tour;
}

}  // namespace sim
}  // namespace picker_localisation
