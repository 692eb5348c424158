#include "picker_localisation/tpf/topological_particle_filter.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace picker_localisation {
namespace tpf {

using topology::NodeIndex;

namespace {
constexpr double kLogHalf = -0.69314718055994530942;  // log(1/2)
constexpr double kMinEdgeLength = 1e-6;               // m; shorter edges have no direction

// Uniform double in [0, 1) from 53 random bits.
inline double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// Standard normal variates for the resampling noise of Eq. 12 by inverse-transform sampling on a grid:
// entry i is the quantile Phi^-1((i + 1/2) / 4096), so 12 random bits give one N(0, 1) draw (tails cut at
// 3.6 sigma, variance 0.997). The 32 spare bits of each particle's prediction draw then serve both velocity
// components (12 + 12 bits) and the dwell noise (8 bits: 256 levels over [tau^-, tau^+]), which keeps the
// noise at a few ns per particle instead of ~25 ns with std::normal_distribution.
constexpr int kNormalTableBits = 12;
double inverseNormalCdf(double p) {
  // Safeguarded Newton on Phi(x) - p = 0, Phi(x) = erfc(-x / sqrt 2) / 2: bisection whenever a Newton step
  // leaves the bracket.
  double lo = -10.0, hi = 10.0, x = std::clamp(std::log(p / (1.0 - p)) / 1.702, lo, hi);
  for (int it = 0; it < 200; ++it) {
    const double err = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
    if (err < 0.0)
      lo = x;
    else
      hi = x;
    const double pdf = std::exp(-0.5 * x * x) / std::sqrt(2.0 * M_PI);
    double next = x - err / pdf;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - x) < 1e-14) return next;
    x = next;
  }
  return x;
}
const std::vector<float>& normalTable() {
  static const std::vector<float> table = [] {
    const std::size_t n = std::size_t{1} << kNormalTableBits;
    std::vector<float> t(n);
    for (std::size_t i = 0; i < n / 2; ++i) {
      const float x =
          static_cast<float>(inverseNormalCdf((static_cast<double>(i) + 0.5) / static_cast<double>(n)));
      t[i] = x;
      t[n - 1 - i] = -x;  // exact symmetry: zero mean
    }
    return t;
  }();
  return table;
}
}  // namespace

// Compressed adjacency of the motion graph (successors or undirected neighbours) with the unit direction and
// length of every edge, built once per filter and shared by its copies.
struct TopologicalParticleFilter::MotionGraph {
  struct Arc {
    double ux = 0.0, uy = 0.0;  // unit direction q -> target (0 for a zero-length edge)
    double length = 0.0;        // m
    double rate = 0.0;          // 2 log(1/2) / length (lambda of Eq. 6 per m/s of projected speed), 1/m
    NodeIndex target = topology::kInvalidNode;
  };
  std::vector<std::uint32_t> offsets;  // |N| + 1
  std::vector<Arc> arcs;               // grouped by source node
  std::size_t max_degree = 0;
  double median_arc_length = 0.0;  // m, node spacing (GNSS bias state: where the picker is between nodes)
  // Lane-change paths (TpfParams::lane_change_model): lane end, non-lane nodes..., adjacent lane's end, its
  // next lane node; exits of node n are exit_paths[exit_offsets[n] .. exit_offsets[n + 1]).
  std::vector<std::vector<NodeIndex>> lane_paths;
  std::vector<Eigen::Vector2d> lane_path_shift;  // adjacent lane's end minus the lane end left, m
  std::vector<std::uint32_t> exit_offsets, exit_paths;

  // Lane hypotheses (TpfParams::lane_swap_rate): per lane node, the nearest node of another lane on each side
  // of its lane (across[2 n], across[2 n + 1]; kInvalidNode when none), at most max_distance away and within
  // 45 degrees of the lane's normal.
  std::vector<NodeIndex> across;

  // Unit normal of a lane's axis (principal axis of its node positions).
  static Eigen::Vector2d laneNormal(const topology::TopologicalMap& map,
                                    const std::vector<NodeIndex>& nodes) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (NodeIndex i : nodes) mean += map.position2d(i);
    mean /= static_cast<double>(nodes.size());
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (NodeIndex i : nodes) {
      const Eigen::Vector2d d = map.position2d(i) - mean;
      cov += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    const Eigen::Vector2d axis = eig.eigenvectors().col(1);
    return {-axis.y(), axis.x()};
  }

  // Calls visit(lane, its nodes, its unit normal) for every lane of at least two nodes. "Sides" of a lane are
  // the two half-planes of its normal.
  template <typename Visit>
  static void forEachLane(const topology::TopologicalMap& map, Visit visit) {
    for (std::size_t l = 0; l < map.numLanes(); ++l) {
      const auto lane = static_cast<topology::LaneIndex>(l);
      const auto& nodes = map.laneNodes(lane);
      if (nodes.size() >= 2) visit(lane, nodes, laneNormal(map, nodes));
    }
  }

  void buildAcrossLanes(const topology::TopologicalMap& map, double max_distance) {
    across.assign(2 * map.numNodes(), topology::kInvalidNode);
    forEachLane(map, [&](topology::LaneIndex lane, const std::vector<NodeIndex>& nodes,
                         const Eigen::Vector2d& normal) {
      for (NodeIndex e : nodes) {
        const Eigen::Vector2d pe = map.position2d(e);
        double best[2] = {max_distance, max_distance};
        for (NodeIndex k : map.nodesWithin(pe, max_distance)) {
          if (map.lane(k) < 0 || map.lane(k) == lane) continue;
          const Eigen::Vector2d d = map.position2d(k) - pe;
          const double side = d.dot(normal), distance = d.norm();
          if (std::abs(side) < std::sqrt(0.5) * distance) continue;  // more along the lane than across it
          const int s = side > 0.0 ? 0 : 1;
          if (distance < best[s]) best[s] = distance, across[2 * e + s] = k;
        }
      }
    });
  }

  void buildLaneChangePaths(const topology::TopologicalMap& map, bool directed, int max_hops) {
    const std::size_t n = map.numNodes();
    std::vector<std::vector<std::uint32_t>> exits(n);
    std::vector<int> depth(n, -1);
    std::vector<NodeIndex> parent(n, topology::kInvalidNode), visited;
    forEachLane(map, [&](topology::LaneIndex lane, const std::vector<NodeIndex>& nodes,
                         const Eigen::Vector2d& normal) {
      for (NodeIndex e : nodes) {
        int in_lane = 0;
        for (NodeIndex k : map.motionNeighbours(e, directed)) in_lane += map.lane(k) == lane ? 1 : 0;
        if (in_lane > 1) continue;  // not an end of the lane
        // BFS from the end through non-lane nodes; nodes of other lanes end a path.
        struct Best {
          NodeIndex t = topology::kInvalidNode;
          double dist = 1e300;
        } best[2];
        visited.clear();
        depth[e] = 0;
        visited.push_back(e);
        for (std::size_t head = 0; head < visited.size(); ++head) {
          const NodeIndex a = visited[head];
          if (depth[a] >= max_hops || (a != e && map.lane(a) >= 0)) continue;
          for (NodeIndex k : map.motionNeighbours(a, directed)) {
            if (depth[k] >= 0 || map.lane(k) == lane) continue;
            depth[k] = depth[a] + 1;
            parent[k] = a;
            visited.push_back(k);
            if (map.lane(k) < 0) continue;
            const Eigen::Vector2d d = map.position2d(k) - map.position2d(e);
            const double side = d.dot(normal);
            if (std::abs(side) < 0.1) continue;  // straight ahead: not a neighbouring lane
            Best& b = best[side > 0.0 ? 0 : 1];
            if (d.norm() < b.dist) b = {k, d.norm()};
          }
        }
        for (const Best& b : best) {
          if (b.t == topology::kInvalidNode) continue;
          std::vector<NodeIndex> path;
          for (NodeIndex k = b.t; k != e; k = parent[k]) path.push_back(k);
          path.push_back(e);
          std::reverse(path.begin(), path.end());
          const auto target_lane = map.lane(b.t);
          for (NodeIndex k : map.motionNeighbours(b.t, directed))
            if (map.lane(k) == target_lane) {
              path.push_back(k);  // one node into the new lane: the particle then walks along it
              break;
            }
          exits[e].push_back(static_cast<std::uint32_t>(lane_paths.size()));
          // From lane end to the adjacent lane's end (not to the path's last node, one node along the new
          // lane: along-lane steps would swamp the 1.5 m sideways shift in the dot products of sideWeight).
          lane_path_shift.push_back(map.position2d(path[path.size() - 2]) - map.position2d(path.front()));
          lane_paths.push_back(std::move(path));
        }
        for (NodeIndex k : visited) depth[k] = -1;
      }
    });
    exit_offsets.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
      exit_offsets[i + 1] = exit_offsets[i] + static_cast<std::uint32_t>(exits[i].size());
      exit_paths.insert(exit_paths.end(), exits[i].begin(), exits[i].end());
    }
  }

  // Side memory (TpfParams::lane_change_keep_side): weight of lane-change path `path` for a particle whose
  // last completed lane change was `last` (1 + index; 0: none): keep when both shift the same way, 1 - keep
  // when they shift opposite ways, 0.5 when there is no memory or the shifts are perpendicular.
  double sideWeight(std::uint32_t path, std::uint32_t last, double keep) const {
    if (last == 0) return 0.5;
    const double dot = lane_path_shift[path].dot(lane_path_shift[last - 1]);
    return dot > 0.0 ? keep : (dot < 0.0 ? 1.0 - keep : 0.5);
  }
  // Factor on the jump from `from` to `to` at a turn: twice the mean side weight of the lane-change paths of
  // `from` starting with that jump (1 when none: the back edge, or a node both sides share equally).
  double exitWeight(NodeIndex from, NodeIndex to, std::uint32_t last, double keep) const {
    if (exit_offsets.empty() || last == 0) return 1.0;
    double sum = 0.0;
    int count = 0;
    for (std::uint32_t k = exit_offsets[from]; k < exit_offsets[from + 1]; ++k)
      if (lane_paths[exit_paths[k]][1] == to) sum += sideWeight(exit_paths[k], last, keep), ++count;
    return count ? 2.0 * sum / count : 1.0;
  }

  // A particle jumped from `from` to `to`, leaving its lane: 1 + the index of a lane-change path of `from`
  // whose first step is that jump (the jump chose the side; when both sides share the first node, one drawn
  // by side weight: at random without a memory), or 0 when there is none or the path already ends at `to`.
  std::uint32_t exitPathStartingWith(NodeIndex from, NodeIndex to, std::mt19937_64& rng, std::uint32_t last,
                                     double keep) const {
    if (exit_offsets.empty()) return 0;
    const std::uint32_t begin = exit_offsets[from], end = exit_offsets[from + 1];
    auto starts_with_to = [&](std::uint32_t k) { return lane_paths[exit_paths[k]][1] == to; };
    std::uint32_t found = 0;
    for (std::uint32_t k = begin; k < end; ++k) found += starts_with_to(k) ? 1 : 0;
    if (found == 0) return 0;
    if (found > 1 && last != 0 && keep != 0.5) {
      double total = 0.0;
      for (std::uint32_t k = begin; k < end; ++k)
        if (starts_with_to(k)) total += sideWeight(exit_paths[k], last, keep);
      double u = static_cast<double>(rng() >> 11) * 0x1.0p-53 * total;
      for (std::uint32_t k = begin; k < end; ++k) {
        if (!starts_with_to(k)) continue;
        u -= sideWeight(exit_paths[k], last, keep);
        if (u < 0.0) return lane_paths[exit_paths[k]].back() == to ? 0 : exit_paths[k] + 1;
      }
    }
    std::uint32_t skip = found > 1 ? static_cast<std::uint32_t>(rng() % found) : 0;
    for (std::uint32_t k = begin; k < end; ++k)
      if (starts_with_to(k) && skip-- == 0)
        return lane_paths[exit_paths[k]].back() == to ? 0 : exit_paths[k] + 1;
    return 0;
  }

  MotionGraph(const topology::TopologicalMap& map, bool directed, bool lane_change, int max_hops,
              double lane_swap_distance) {
    const std::size_t n = map.numNodes();
    offsets.resize(n + 1, 0);
    for (NodeIndex i = 0; i < n; ++i) {
      const auto& nb = map.motionNeighbours(i, directed);
      offsets[i + 1] = offsets[i] + static_cast<std::uint32_t>(nb.size());
      max_degree = std::max(max_degree, nb.size());
      const Eigen::Vector2d pi = map.position2d(i);
      for (NodeIndex k : nb) {
        const Eigen::Vector2d d = map.position2d(k) - pi;
        Arc a;
        a.length = d.norm();
        a.target = k;
        if (a.length > kMinEdgeLength) {
          a.ux = d.x() / a.length;
          a.uy = d.y() / a.length;
          a.rate = 2.0 * kLogHalf / a.length;
        }
        arcs.push_back(a);
      }
    }
    if (!arcs.empty()) {
      std::vector<double> lengths;
      lengths.reserve(arcs.size());
      for (const Arc& a : arcs) lengths.push_back(a.length);
      std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
      median_arc_length = lengths[lengths.size() / 2];
    }
    if (lane_change) buildLaneChangePaths(map, directed, max_hops);
    if (lane_swap_distance > 0.0) buildAcrossLanes(map, lane_swap_distance);
  }
};

const char* toString(UpdateStatus s) {
  switch (s) {
    case UpdateStatus::kAccepted:
      return "accepted";
    case UpdateStatus::kReordered:
      return "reordered";
    case UpdateStatus::kDroppedTooOld:
      return "dropped_too_old";
    case UpdateStatus::kIgnoredSensor:
      return "ignored_sensor";
    case UpdateStatus::kRejectedInvalid:
      return "rejected_invalid";
  }
  return "unknown";
}

double Belief::massOf(NodeIndex n) const {
  auto it = std::lower_bound(nodes.begin(), nodes.end(), n);
  return (it != nodes.end() && *it == n) ? masses[static_cast<std::size_t>(it - nodes.begin())] : 0.0;
}

TopologicalParticleFilter::TopologicalParticleFilter(std::shared_ptr<const topology::TopologicalMap> map,
                                                     TpfParams params, std::uint64_t seed)
    : map_(std::move(map)), params_(std::move(params)), seed_(seed), rng_(seed) {
  if (!map_ || map_->numNodes() == 0) throw std::invalid_argument("TopologicalParticleFilter: empty map");
  const std::string problem = params_.validate();
  if (!problem.empty()) throw std::invalid_argument("TopologicalParticleFilter: " + problem);
  useMap(map_);
  reset();
}

void TopologicalParticleFilter::useMap(std::shared_ptr<const topology::TopologicalMap> map) {
  // What can throw (std::bad_alloc) first, into locals; then no-throw swaps: a failure leaves the filter as
  // it was.
  auto graph = std::make_shared<const MotionGraph>(
      *map, params_.directed_motion,
      params_.lane_change_model && params_.motion_model == MotionModel::kVelocity,
      params_.lane_change_max_hops,
      (params_.gnss_bias_state && params_.lane_swap_rate > 0.0) || params_.lane_evidence_sweeps > 0 ||
              params_.lane_evidence_projection
          ? params_.lane_swap_max_distance
          : 0.0);
  std::vector<double> edge(std::max<std::size_t>(1, graph->max_degree), 0.0);
  std::vector<double> projection(edge.size(), 0.0), node_a(map->numNodes(), 0.0),
      node_b(map->numNodes(), 0.0);
  std::vector<double> lanes(map->numLanes(), 0.0);
  map_.swap(map);
  graph_.swap(graph);
  edge_scratch_.swap(edge);
  projection_scratch_.swap(projection);
  node_scratch_a_.swap(node_a);
  node_scratch_b_.swap(node_b);
  lane_scratch_.swap(lanes);
  touched_.clear();
  // GNSS bias state: a fix spreads about the particle's node by gnss_bias_fix_std plus where the picker is
  // between nodes (uniform over the node spacing: variance spacing^2 / 12), from the map, not tuned to one.
  bias_fix_variance_ = params_.gnss_bias_fix_std * params_.gnss_bias_fix_std +
                       graph_->median_arc_length * graph_->median_arc_length / 12.0;
}

void TopologicalParticleFilter::adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                                         const std::vector<topology::NodeIndex>& old_to_new) {
  if (!map || map->numNodes() == 0) throw std::invalid_argument("adoptMap: empty map");
  if (old_to_new.size() != map_->numNodes())
    throw std::invalid_argument("adoptMap: the mapping has " + std::to_string(old_to_new.size()) +
                                " entries for " + std::to_string(map_->numNodes()) + " nodes");
  for (topology::NodeIndex n : old_to_new)
    if (n >= map->numNodes()) throw std::invalid_argument("adoptMap: the mapping names a node the map lacks");
  useMap(std::move(map));  // throws before changing anything
  for (Particle& p : particles_) {
    p.node = old_to_new[p.node];
    p.lane_change = 0;
    p.last_lane_change = 0;
  }
  if (!particles_.empty()) recordBelief(false);  // the support and n* on the new map's nodes
}

void TopologicalParticleFilter::reset() {
  particles_.clear();
  resampled_.clear();
  weights_.clear();
  touched_.clear();
  belief_ = Belief();
  bias_stamp_ = 0.0;
  bias_step_ = 0.0;
  other_sensor_stamp_ = -std::numeric_limits<double>::infinity();
  bias_prior_mean_.setZero();
  bias_prior_variance_ = 0.0;
  bias_drift_rate_ = 0.0;
  unconnected_p_ = params_.unconnected_jump_probability;
  belief_.unconnected_jump_probability = unconnected_p_;
}

// ------------------------------------------------------------------------------------------ equations ------
double TopologicalParticleFilter::lambda(double projected_speed, double distance) {
  // Eq. 6. A zero-length edge has no direction to move along: lambda 0 (no jump).
  if (!(distance > kMinEdgeLength)) return 0.0;
  return 2.0 * kLogHalf * std::max(0.0, projected_speed) / distance;
}

double TopologicalParticleFilter::edgeJumpProbability(double lambda, double dwell) {
  return 1.0 - std::exp(lambda * std::max(0.0, dwell));
}

std::vector<double> TopologicalParticleFilter::transitionProbabilities(NodeIndex node, double vx, double vy,
                                                                       double dwell) const {
  const MotionGraph& g = *graph_;
  const std::uint32_t begin = g.offsets.at(node), end = g.offsets.at(node + 1);
  std::vector<double> out(end - begin, 0.0);
  if (begin == end) return out;
  if (params_.motion_model == MotionModel::kFixedLambda) {
    // Khan et al. Eq. 2: r = 1 - exp(-lambda tau), target uniform among the connected nodes.
    const double r = 1.0 - std::exp(-params_.fixed_lambda * std::max(0.0, dwell));
    for (auto& p : out) p = r / static_cast<double>(out.size());
    return out;
  }
  std::vector<double> b(out.size());
  double sum_b = 0.0, max_b = 0.0;
  for (std::uint32_t e = begin; e < end; ++e) {
    b[e - begin] = std::max(0.0, vx * g.arcs[e].ux + vy * g.arcs[e].uy);
    max_b = std::max(max_b, b[e - begin]);
  }
  const double speed = std::sqrt(vx * vx + vy * vy);
  if (max_b < params_.turn_projection_fraction * speed)  // turning (see predict())
    for (std::uint32_t e = begin; e < end; ++e)
      b[e - begin] = g.arcs[e].length > kMinEdgeLength ? speed : 0.0;
  for (double x : b) sum_b += x;
  if (!(sum_b > 0.0)) return out;
  for (std::uint32_t e = begin; e < end; ++e)
    out[e - begin] =
        b[e - begin] * edgeJumpProbability(lambda(b[e - begin], g.arcs[e].length), dwell) / sum_b;
  return out;
}

double TopologicalParticleFilter::jumpProbability(NodeIndex node, double vx, double vy, double dwell) const {
  double s = 0.0;
  for (double p : transitionProbabilities(node, vx, vy, dwell)) s += p;
  return s;
}

double TopologicalParticleFilter::particleWeight(const Particle& p, double normalised_likelihood,
                                                 const core::Observation& obs) const {
  const SensorGamma gamma = params_.gammaFor(obs.sensor);
  double w = gamma.node * normalised_likelihood;
  if (obs.velocity && gamma.velocity > 0.0 && params_.motion_model == MotionModel::kVelocity) {
    const double vs = obs.velocity->norm();
    const double sigma = std::max(0.5 * vs, params_.min_velocity_sigma);
    const double speed =
        p.standing ? 0.0 : std::sqrt(static_cast<double>(p.vx) * p.vx + static_cast<double>(p.vy) * p.vy);
    const double z = (speed - vs) / sigma;
    const double g = std::exp(-0.5 * z * z);  // Gaussian of Eq. 8, peak 1
    // cos of the angle between the particle and the observed velocity; 0 (no preference) if either is zero.
    const double denom = speed * vs;
    const double cosang = denom > 1e-12 ? (p.vx * obs.velocity->x() + p.vy * obs.velocity->y()) / denom : 0.0;
    const double wv = gamma.velocity * 0.25 * (g + 0.5 * (cosang + 1.0));
    w = params_.velocity_weight_product ? w * (1.0 + wv) : w + wv;
  }
  return w;
}

double TopologicalParticleFilter::jensenShannonDistance(const std::vector<std::pair<NodeIndex, double>>& p,
                                                        const std::vector<std::pair<NodeIndex, double>>& q) {
  auto sorted = [](std::vector<std::pair<NodeIndex, double>> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  const auto a = sorted(p), b = sorted(q);
  auto term = [](double x, double y) {  // x log2(2x / (x + y))
    return x > 0.0 ? x * std::log2(2.0 * x / (x + y)) : 0.0;
  };
  double s = 0.0;
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    double x = 0.0, y = 0.0;
    if (j == b.size() || (i < a.size() && a[i].first < b[j].first)) {
      x = a[i++].second;
    } else if (i == a.size() || b[j].first < a[i].first) {
      y = b[j++].second;
    } else {
      x = a[i++].second;
      y = b[j++].second;
    }
    s += term(x, y) + term(y, x);
  }
  return std::sqrt(std::clamp(0.5 * s, 0.0, 1.0));
}

double TopologicalParticleFilter::entropy(const std::vector<double>& probabilities) {
  double h = 0.0;
  for (double p : probabilities)
    if (p > 0.0) h -= p * std::log(p);
  return h;
}

// ----------------------------------------------------------------------------------------- algorithm ------
UpdateResult TopologicalParticleFilter::reject(UpdateStatus status, std::string reason) {
  switch (status) {
    case UpdateStatus::kDroppedTooOld:
      ++counters_.dropped_too_old;
      break;
    case UpdateStatus::kIgnoredSensor:
      ++counters_.ignored_sensor;
      break;
    default:
      ++counters_.rejected_invalid;
      break;
  }
  UpdateResult r;
  r.status = status;
  r.reason = std::move(reason);
  return r;
}

UpdateResult TopologicalParticleFilter::update(const core::Observation& obs, double association_probability) {
  if (!params_.acceptsSensor(obs.sensor))
    return reject(UpdateStatus::kIgnoredSensor, "sensor '" + obs.sensor + "' is not fused in this mode");
  const std::string problem = core::validateObservation(obs, *map_);
  if (!problem.empty()) return reject(UpdateStatus::kRejectedInvalid, problem);

  UpdateResult result;
  double dt = 0.0;
  if (!belief_.initialised) {
    initialise(obs);
    belief_.initialised = true;
    belief_.stamp = obs.stamp;
    result.initialised = true;
  } else if (obs.stamp < belief_.stamp) {
    const double late = belief_.stamp - obs.stamp;
    if (late > params_.reorder_window)
      return reject(UpdateStatus::kDroppedTooOld, "observation " + std::to_string(late) +
                                                      " s older than the last update (reorder window " +
                                                      std::to_string(params_.reorder_window) + " s)");
    result.status = UpdateStatus::kReordered;
  } else {
    dt = obs.stamp - belief_.stamp;
  }
  fuse(obs, dt, result, association_probability);
  if (!params_.usesBiasState(obs.sensor)) other_sensor_stamp_ = std::max(other_sensor_stamp_, obs.stamp);
  if (result.status == UpdateStatus::kReordered)
    ++counters_.reordered;
  else
    ++counters_.accepted;
  ++belief_.observations;
  belief_.stamp = std::max(belief_.stamp, obs.stamp);
  return result;
}

bool TopologicalParticleFilter::predictTo(double stamp) {
  if (!belief_.initialised || !std::isfinite(stamp) || !(stamp > belief_.stamp)) return false;
  predict(stamp - belief_.stamp);
  belief_.stamp = stamp;
  belief_.reinitialised = false;
  ++counters_.predictions;
  recordBelief(true);
  return true;
}

void TopologicalParticleFilter::initialise(const core::Observation& obs) {
  const std::size_t n = params_.num_particles;
  particles_.resize(n);
  resampled_.resize(n);
  weights_.resize(n);
  spare_bits_.assign(n, 0u);
  redraw(obs, n);
}

void TopologicalParticleFilter::reinitialisePart(const core::Observation& obs, double fraction) {
  // Departure from Alg. 1 l. 6 (reinit_fraction < 1): only every (1/fraction)-th particle is drawn again from
  // Eq. 1, the rest keep the belief. A contradicting observation that is right wins within a few updates (the
  // redrawn particles carry its weight); one that is wrong (an RFID ring 5-8 m from the antenna, a biased
  // fix) no longer scatters the whole belief.
  const double n = static_cast<double>(particles_.size());
  redraw(obs, std::max<std::size_t>(1, static_cast<std::size_t>(fraction * n)));
}

void TopologicalParticleFilter::redraw(const core::Observation& obs, std::size_t count) {
  // Eq. 1 for `count` particles spread evenly over the set (every particle when count = size): q ~ L / sum L
  // (uniform over the whole map when the observation does not identify the picker), v ~ N(mu_init,
  // sigma^2_init) per component, tau ~ U(tau^-_init, tau^+_init). Resets p_rj (Alg. 1 l. 8). L sums to > 0
  // (validateObservation).
  const std::size_t n = particles_.size();
  std::normal_distribution<double> vel(params_.velocity_init_mean, std::sqrt(params_.velocity_init_variance));
  std::vector<double> cumulative;
  if (obs.identifying) {
    cumulative.reserve(obs.likelihood.size());
    double c = 0.0;
    for (double l : obs.likelihood) cumulative.push_back(c += l);
  }
  const double span = params_.dwell_init_max - params_.dwell_init_min;
  for (std::size_t j = 0; j < count; ++j) {
    Particle& p = particles_[(j * n) / count];
    if (obs.identifying) {
      const double u = uniform01(rng_) * cumulative.back();
      std::size_t k = static_cast<std::size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), u) -
                                               cumulative.begin());
      k = std::min(k, cumulative.size() - 1);
      p.node = obs.nodes[k];
    } else {
      p.node = static_cast<NodeIndex>(rng_() % map_->numNodes());
    }
    p.vx = static_cast<float>(vel(rng_));
    p.vy = static_cast<float>(vel(rng_));
    p.dwell = static_cast<float>(params_.dwell_init_min + span * uniform01(rng_));
    p.lane_change = 0;
    p.last_lane_change = 0;
    p.standing = false;
    p.bias_variance = -1.0f;  // the bias starts from the next GNSS fix's prior
  }
  unconnected_p_ = params_.unconnected_jump_probability;
}

void TopologicalParticleFilter::predict(double dt) {
  // Eqs. 2-7, one jump at most per particle and step; see the header for the reading of Eqs. 3 and 7.
  // The same pass counts the predicted particles per node (node_scratch_b_, touched_) for the JSD / belief.
  touched_.clear();
  if (params_.motion_model == MotionModel::kFixedLambda) {
    predictFixedLambda(dt);
    return;
  }
  reverseSomeVelocities(dt);
  switchStanding(dt);
  std::vector<double>& count = node_scratch_b_;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    if (particles_[i].standing) {
      spare_bits_[i] = static_cast<std::uint32_t>(rng_() >> 32);  // addNoise's draw, as for a walking one
      particles_[i].dwell = 0.0f;  // it walks on from a standstill: Eqs. 2-3's dwell restarts
    } else {
      moveWithVelocityModel(i, dt);
    }
    const NodeIndex n = particles_[i].node;
    if (count[n] == 0.0) touched_.push_back(n);
    count[n] += 1.0;
  }
}

void TopologicalParticleFilter::predictFixedLambda(double dt) {
  // Khan et al. 2020: every particle leaves its node at the fixed rate lambda, to a neighbour chosen
  // uniformly.
  const MotionGraph& g = *graph_;
  std::vector<double>& count = node_scratch_b_;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    Particle& p = particles_[i];
    const double tau = static_cast<double>(p.dwell) + dt;
    const std::uint32_t begin = g.offsets[p.node], end = g.offsets[p.node + 1];
    const std::uint64_t bits = rng_();
    spare_bits_[i] = static_cast<std::uint32_t>(bits >> 32);
    const double u = static_cast<double>(bits & 0xffffffffu) * 0x1.0p-32;
    // Exponential dwell (Khan et al. 2020): the cumulative 1 - exp(-lambda tau) at every step, Eq. 2 read
    // literally.
    const double r = 1.0 - std::exp(-params_.fixed_lambda * tau);
    if (begin == end || !(u < r)) {
      p.dwell = static_cast<float>(tau);
    } else {
      // u / r is uniform in [0, 1) given a jump: reuse it to pick the neighbour.
      const std::uint32_t k =
          begin +
          std::min<std::uint32_t>(end - begin - 1, static_cast<std::uint32_t>((u / r) * (end - begin)));
      p.node = g.arcs[k].target;
      p.dwell = 0.0f;
    }
    if (count[p.node] == 0.0) touched_.push_back(p.node);
    count[p.node] += 1.0;
  }
}

void TopologicalParticleFilter::reverseSomeVelocities(double dt) {
  // Not in the paper: pickers turn round in the middle of a lane (Table I p_reverse). Without a turn the
  // velocity model cannot follow them (the back edge has b = 0), so each particle reverses its velocity with
  // probability 1 - exp(-reverse_rate dt) per step (geometric gaps: one draw per reversing particle).
  if (!(params_.reverse_rate > 0.0 && dt > 0.0)) return;
  const double p_rev = 1.0 - std::exp(-params_.reverse_rate * dt);
  if (!(p_rev > 0.0)) return;
  std::geometric_distribution<std::size_t> gap(std::min(p_rev, 1.0));
  for (std::size_t i = gap(rng_); i < particles_.size(); i += 1 + gap(rng_)) {
    particles_[i].vx = -particles_[i].vx;
    particles_[i].vy = -particles_[i].vy;
  }
}

void TopologicalParticleFilter::switchStanding(double dt) {
  // Not in the paper (TpfParams::stand_rate): a two-state Markov chain per particle, walking -> standing at
  // stand_rate, standing -> walking at walk_rate. Candidates are drawn with geometric gaps at the larger of
  // the two step probabilities and switch with the ratio of their own state's to it (one draw per candidate).
  if (!(params_.stand_rate > 0.0 && dt > 0.0)) return;
  const double p_stand = 1.0 - std::exp(-params_.stand_rate * dt);
  const double p_walk = 1.0 - std::exp(-params_.walk_rate * dt);
  const double p_max = std::min(1.0, std::max(p_stand, p_walk));
  if (!(p_max > 0.0)) return;
  std::geometric_distribution<std::size_t> gap(p_max);
  for (std::size_t i = gap(rng_); i < particles_.size(); i += 1 + gap(rng_)) {
    Particle& p = particles_[i];
    if (!(uniform01(rng_) * p_max < (p.standing ? p_walk : p_stand))) continue;
    p.standing = !p.standing;
    // A particle that stops inside a lane on its way in from a lane change has arrived: it is in that lane
    // (the side is remembered as after the path's end). Left on the path, it stayed out of the lane swaps and
    // the lane masses' sharing for as long as it stood, and a standing cloud one lane off held its lane.
    if (p.standing && p.lane_change != 0 && map_->lane(p.node) != topology::kNoLane) {
      p.last_lane_change = p.lane_change;
      p.lane_change = 0;
    }
  }
}

void TopologicalParticleFilter::moveWithVelocityModel(std::size_t i, double dt) {
  // Eqs. 2-7 for one particle: at most one jump per step.
  const MotionGraph& g = *graph_;
  std::vector<double>& contrib = edge_scratch_;  // (sized to the largest degree at construction)
  std::vector<double>& proj = projection_scratch_;
  Particle& p = particles_[i];
  const double tau = static_cast<double>(p.dwell) + dt;
  const std::uint32_t begin = g.offsets[p.node], end = g.offsets[p.node + 1];
  const std::uint64_t bits = rng_();
  spare_bits_[i] = static_cast<std::uint32_t>(bits >> 32);
  // Per arc: b (Eq. 2) and the survival e1 = exp(lambda tau) at the dwell reached. Jump to k in this step
  // with probability b_k (1 - e1_k) / sum b: Eqs. 2-3 at tau, read literally.
  const NodeIndex path_next = projectOnEdges(p);
  double sum_b = 0.0, sum_c = 0.0;
  for (std::uint32_t e = begin; e < end; ++e) {
    const auto& arc = g.arcs[e];
    const double b = proj[e - begin];
    double c = 0.0;
    if (b > 0.0) {
      // exp(lambda tau), lambda of Eq. 6; single precision is ample for a probability and twice as fast.
      const double e1 = std::exp(static_cast<float>(arc.rate * b * tau));
      c = b * (1.0 - e1);
      proj[e - begin] = b * (1.0 - e1);  // b is no longer needed: keep Eq. 2-3's term for Eq. 7
    } else {
      proj[e - begin] = 0.0;
    }
    contrib[e - begin] = c;
    sum_b += b;
    sum_c += c;
  }
  const double u = static_cast<double>(bits & 0xffffffffu) * 0x1.0p-32 * sum_b;  // jump w.p. sum_c / sum_b
  if (!(u < sum_c)) {
    p.dwell = static_cast<float>(tau);
  } else {
    std::uint32_t e = begin;
    double acc = contrib[0];
    while (acc <= u && e + 1 < end) acc += contrib[++e - begin];
    // Pr(q') of Eq. 7: Eq. 2-3 probability of the transition taken at the dwell reached (rate independent).
    const double pr = proj[e - begin] / sum_b;
    jumpAlong(p, e, pr, tau, path_next);
  }
}

// b of Eq. 2 for every edge out of p's node, in projection_scratch_; returns the next node of p's lane-change
// path (kInvalidNode when it follows none; a path p has left is forgotten).
NodeIndex TopologicalParticleFilter::projectOnEdges(Particle& p) {
  const MotionGraph& g = *graph_;
  std::vector<double>& proj = projection_scratch_;
  const std::uint32_t begin = g.offsets[p.node], end = g.offsets[p.node + 1];
  const double vx = p.vx, vy = p.vy;
  const double leak = params_.lane_change_leak;
  const double keep = params_.lane_change_keep_side;
  const double turn_fraction = params_.turn_projection_fraction;
  // Turning: when no edge lies within acos(turn_fraction) of the velocity (lane end, corner into the
  // headland), every edge gets b = |v| (see turn_projection_fraction).
  // On a lane-change path: the path's next node gets b = |v|, every other edge lane_change_leak |v|.
  NodeIndex path_next = topology::kInvalidNode;
  if (p.lane_change != 0) {
    const auto& path = g.lane_paths[p.lane_change - 1];
    const auto at = std::find(path.begin(), path.end(), p.node);
    if (at != path.end() && at + 1 != path.end())
      path_next = *(at + 1);
    else
      p.lane_change = 0;
  }
  double max_proj = 0.0;
  if (path_next != topology::kInvalidNode) {
    const double speed = std::sqrt(vx * vx + vy * vy);
    for (std::uint32_t e = begin; e < end; ++e)
      proj[e - begin] = g.arcs[e].length > 0.0 ? (g.arcs[e].target == path_next ? speed : leak * speed) : 0.0;
    max_proj = speed;
  } else {
    for (std::uint32_t e = begin; e < end; ++e) {
      const double b = std::max(0.0, vx * g.arcs[e].ux + vy * g.arcs[e].uy);
      proj[e - begin] = b;
      max_proj = std::max(max_proj, b);
    }
  }
  if (path_next == topology::kInvalidNode && max_proj < turn_fraction * std::sqrt(vx * vx + vy * vy)) {
    const double speed = std::sqrt(vx * vx + vy * vy);
    for (std::uint32_t e = begin; e < end; ++e) proj[e - begin] = g.arcs[e].length > 0.0 ? speed : 0.0;
    if (p.last_lane_change != 0 && keep != 0.5)  // side memory: the remembered side's exit weighs more
      for (std::uint32_t e = begin; e < end; ++e)
        if (proj[e - begin] > 0.0)
          proj[e - begin] *= g.exitWeight(p.node, g.arcs[e].target, p.last_lane_change, keep);
  }
  return path_next;
}

// The jump of Eq. 7 along arc e (Eq. 2-3 probability pr) after dwelling tau: the velocity update, the node,
// and the lane-change path followed or begun.
void TopologicalParticleFilter::jumpAlong(Particle& p, std::uint32_t e, double pr, double tau,
                                          NodeIndex path_next) {
  const MotionGraph& g = *graph_;
  const double inv_window = 1.0 / params_.velocity_window;
  const double vx = p.vx, vy = p.vy;
  const double keep = params_.lane_change_keep_side;
  const bool follow_edge = params_.velocity_follows_edge;
  const double inv_t = 1.0 / std::max(tau, params_.min_jump_dwell);
  const auto& arc = g.arcs[e];
  const double ox = arc.ux * arc.length * inv_t, oy = arc.uy * arc.length * inv_t;
  if (follow_edge) {
    // Departure from Eq. 7 (velocity_follows_edge): Eq. 7 smooths the speed only; the heading becomes the
    // edge taken, so a particle that turned (lane end, headland corner) keeps walking the way it turned
    // instead of pointing back along the lane it left for ~V jumps.
    const double speed = std::sqrt(vx * vx + vy * vy);
    const double s = speed + pr * (arc.length * inv_t - speed) * inv_window;
    p.vx = static_cast<float>(arc.ux * s);
    p.vy = static_cast<float>(arc.uy * s);
  } else {
    p.vx = static_cast<float>(vx + pr * (ox - vx) * inv_window);
    p.vy = static_cast<float>(vy + pr * (oy - vy) * inv_window);
  }
  const NodeIndex from = p.node;
  p.node = arc.target;
  p.dwell = 0.0f;
  if (path_next != topology::kInvalidNode) {
    // Followed the path (ends one node inside the new lane) or left it.
    const auto& path = g.lane_paths[p.lane_change - 1];
    if (arc.target == path_next && path.back() == arc.target) p.last_lane_change = p.lane_change;
    if (arc.target != path_next || path.back() == arc.target) p.lane_change = 0;
  } else if (map_->lane(arc.target) != map_->lane(from)) {
    // Left the lane at an end?
    p.lane_change = g.exitPathStartingWith(from, arc.target, rng_, p.last_lane_change, keep);
  }
}

double TopologicalParticleFilter::observationJsd(const core::Observation& obs, double sum_likelihood,
                                                 double max_likelihood, double* mean_likelihood) {
  // JSD between the particles' node distribution Q and L / sum L over their joint support, in O(support),
  // and the mean of L / max L over the particles. node_scratch_b_ / touched_ hold the predicted particle
  // counts left by predict() (cleared here); node_scratch_a_ holds L (raw) at the observation's nodes.
  std::vector<double>& count = node_scratch_b_;
  const double inv_n = 1.0 / static_cast<double>(particles_.size());
  auto term = [](double x, double y) { return x > 0.0 ? x * std::log2(2.0 * x / (x + y)) : 0.0; };
  double s = 0.0, mean = 0.0;
  for (NodeIndex n : touched_) {
    const double q = count[n] * inv_n, l = node_scratch_a_[n] / sum_likelihood;
    s += term(q, l) + term(l, q);
    mean += q * node_scratch_a_[n] / max_likelihood;
  }
  for (std::size_t j = 0; j < obs.nodes.size(); ++j)
    if (count[obs.nodes[j]] == 0.0) s += obs.likelihood[j] / sum_likelihood;  // q = 0: l log2(2) = l
  for (NodeIndex n : touched_) count[n] = 0.0;
  if (mean_likelihood) *mean_likelihood = mean;
  return std::sqrt(std::clamp(0.5 * s, 0.0, 1.0));
}

void TopologicalParticleFilter::fuse(const core::Observation& obs, double dt, UpdateResult& result,
                                     double association_probability) {
  predict(dt);  // Alg. 1 l. 4

  double sum_l = 0.0, max_l = 0.0;
  for (std::size_t j = 0; j < obs.nodes.size(); ++j) {
    node_scratch_a_[obs.nodes[j]] = obs.likelihood[j];
    sum_l += obs.likelihood[j];
    max_l = std::max(max_l, obs.likelihood[j]);
  }
  double mean_l = 0.0;
  belief_.jsd = observationJsd(obs, sum_l, max_l, &mean_l);  // Alg. 1 l. 5
  belief_.reinitialised = false;
  // Alg. 1 l. 6, with the guard that the observation must contradict the particles (mean L / max L below
  // reinit_max_mean_likelihood): a flat, negative-information likelihood ("not near this antenna") is far
  // from a concentrated belief in JSD yet agrees with it, and must not spread the belief over the map.
  const bool may_reinit = params_.reinit_sensors.empty() ||
                          std::find(params_.reinit_sensors.begin(), params_.reinit_sensors.end(),
                                    obs.sensor) != params_.reinit_sensors.end();
  if (params_.jsd_monitor && may_reinit && obs.identifying && belief_.jsd > params_.jsd_threshold &&
      !result.initialised &&
      (mean_l < params_.reinit_max_mean_likelihood || params_.reinit_max_mean_likelihood >= 1.0)) {
    if (params_.reinit_fraction >= 1.0)
      initialise(obs);  // Alg. 1 l. 6-9 (initialise() sets p_rj back to its initial value, l. 8)
    else
      reinitialisePart(obs, params_.reinit_fraction);
    belief_.reinitialised = true;
    result.reinitialised = true;
    ++counters_.reinitialisations;
  }
  if (params_.lane_evidence_projection && obs.identifying && params_.isLaneEvidence(obs.sensor) &&
      !result.reinitialised && !result.initialised && max_l > 0.0) {
    // TpfParams::lane_evidence_projection: the evidence moves the particles; no weighting follows.
    const std::size_t moved = projectOntoLaneEvidence(max_l);
    for (NodeIndex n : obs.nodes) node_scratch_a_[n] = 0.0;
    recordBelief(false);
    if (moved > 0) {
      ++counters_.lane_evidence_projections;
      result.reason = std::to_string(moved) + " particles moved across into the lane the evidence names";
    }
    if (params_.entropy_gate && belief_.entropy < params_.entropy_threshold) unconnected_p_ = 0.0;
    belief_.unconnected_jump_probability = unconnected_p_;
    return;
  }
  // TpfParams::anonymous_min_support: a person naming no picker whom the particles barely explain is someone
  // else (their equal weights below), not a reason to pull the cloud onto its few stray particles.
  // (Only an identifying observation re-initialises, above.)
  const bool someone_else = !obs.identifying && mean_l < params_.anonymous_min_support;
  // TpfParams::weigh_anonymous_by_association / weigh_named_by_association: the probability that the person
  // is this picker.
  const bool weigh_by_association =
      obs.identifying ? params_.weigh_named_by_association : params_.weigh_anonymous_by_association;
  const double rho = weigh_by_association ? std::clamp(association_probability, 0.0, 1.0) : 1.0;
  const bool overlap = weightAndResample(obs, max_l, someone_else || rho <= 0.0, rho);  // Alg. 1 l. 10-11
  for (NodeIndex n : obs.nodes) node_scratch_a_[n] = 0.0;
  if (someone_else) {
    ++counters_.someone_else;
    result.reason =
        "an unidentified person the particles barely explain (anonymous_min_support): someone else";
  } else if (!overlap) {
    ++counters_.no_overlap;
    result.reason = "no overlap between the observation and the particles: resampled with equal weights";
  }
  // Alg. 1 l. 12-15
  if (params_.entropy_gate && belief_.entropy < params_.entropy_threshold) unconnected_p_ = 0.0;
  belief_.unconnected_jump_probability = unconnected_p_;
}

bool TopologicalParticleFilter::weightAndResample(const core::Observation& obs, double max_likelihood,
                                                  bool equal_weights, double association_probability) {
  // Eq. 8 per particle (as particleWeight(), constants hoisted) with the Eq. 9 masses accumulated in
  // node_scratch_b_ in the same pass; Eq. 10 MAP; Eqs. 11-12. Returns false when every weight was 0.
  const double inv_max = 1.0 / max_likelihood;
  const SensorGamma gamma = params_.gammaFor(obs.sensor);
  const bool velocity_term =
      obs.velocity && gamma.velocity > 0.0 && params_.motion_model == MotionModel::kVelocity;
  const double gq = gamma.node * inv_max;
  // Node term of Eq. 8: gamma_q L^(q), or with the GNSS bias state gamma_q times the fix's predictive density
  // given the particle's own bias (scaled to max 1).
  const bool bias_state = params_.usesBiasState(obs.sensor) && obs.position && obs.bias_removed;
  if (bias_state) weighWithBiasState(obs);
  auto node_term = [&](std::size_t i, NodeIndex n) {
    return (bias_state ? gamma.node * weights_[i] : gq * node_scratch_a_[n]);
  };
  std::vector<double>& mass = node_scratch_b_;
  touched_.clear();
  double total = 0.0;
  auto deposit = [&](NodeIndex n, double w) {
    if (!(w > 0.0)) return;  // a share that underflowed: the node is listed once, with a positive mass
    if (mass[n] == 0.0) touched_.push_back(n);
    mass[n] += w;
  };
  // TpfParams::lane_masses_by_swap_prior: the Eq. 9 masses Rao-Blackwellised over the lane swap.
  const SwapPrior lane_prior =
      bias_state && params_.lane_masses_by_swap_prior && swapsRun(obs) ? swapPrior() : SwapPrior{};
  auto accumulate = [&](std::size_t i, NodeIndex n, double w) {
    weights_[i] = w;
    total += w;
    if (!(w > 0.0)) return;
    if (lane_prior.known())
      shareOverLanes(particles_[i], w, lane_prior, deposit);
    else
      deposit(n, w);
  };
  // TpfParams::weigh_anonymous_by_association, the PDA update (Bar-Shalom and Tse 1975): with probability rho
  // the person is this picker (particle i's Eq. 8 weight w_i), else someone else (the same weight for every
  // particle, the mean of w), so the two hypotheses keep rho : 1 - rho of the mass. Two passes: the mean
  // first.
  const bool mixed = association_probability < 1.0;
  auto weigh = [&](auto&& weight_of) {
    if (!mixed) {
      for (std::size_t i = 0; i < particles_.size(); ++i) accumulate(i, particles_[i].node, weight_of(i));
      return;
    }
    double sum = 0.0;
    for (std::size_t i = 0; i < particles_.size(); ++i) sum += (weights_[i] = weight_of(i));
    const double someone_else_weight = sum > 0.0 ? (1.0 - association_probability) / association_probability *
                                                       sum / static_cast<double>(particles_.size())
                                                 : 0.0;  // 0: no overlap, handled below
    for (std::size_t i = 0; i < particles_.size(); ++i)
      accumulate(i, particles_[i].node, weights_[i] + someone_else_weight);
  };
  if (equal_weights) {
    // the !overlap branch below
  } else if (!velocity_term) {
    weigh([&](std::size_t i) { return node_term(i, particles_[i].node); });
  } else {
    const float ox = static_cast<float>(obs.velocity->x()), oy = static_cast<float>(obs.velocity->y());
    const float vs = std::sqrt(ox * ox + oy * oy);
    const float inv_sigma = 1.0f / static_cast<float>(std::max(0.5 * vs, params_.min_velocity_sigma));
    const float gv4 = static_cast<float>(0.25 * gamma.velocity);
    const bool product = params_.velocity_weight_product;
    weigh([&](std::size_t i) {
      const Particle& p = particles_[i];
      const float speed = p.standing ? 0.0f : std::sqrt(p.vx * p.vx + p.vy * p.vy);
      const float z = (speed - vs) * inv_sigma;
      const float denom = speed * vs;
      const float cosang = denom > 1e-12f ? (p.vx * ox + p.vy * oy) / denom : 0.0f;
      const double wq = node_term(i, p.node);
      const double wv = static_cast<double>(gv4 * (std::exp(-0.5f * z * z) + 0.5f * (cosang + 1.0f)));
      return product ? wq * (1.0 + wv) : wq + wv;
    });
  }
  const bool overlap = total > 0.0 && std::isfinite(total);
  if (!overlap) {
    // The observation says nothing about where these particles are: equal weights, so resampling keeps the
    // set (up to the Eq. 12 noise, which still lets particles jump to unconnected nodes with p_rj).
    for (NodeIndex n : touched_) mass[n] = 0.0;
    touched_.clear();
    total = 0.0;
    for (std::size_t i = 0; i < particles_.size(); ++i) accumulate(i, particles_[i].node, 1.0);
  }
  std::sort(touched_.begin(), touched_.end());
  belief_.nodes.assign(touched_.begin(), touched_.end());
  belief_.masses.resize(touched_.size());
  double best = -1.0;
  for (std::size_t k = 0; k < touched_.size(); ++k) {
    const double m = mass[touched_[k]] / total;
    belief_.masses[k] = m;
    if (m > best) {
      best = m;
      belief_.map_node = touched_[k];
    }
    mass[touched_[k]] = 0.0;
  }
  if (params_.map_node_by_lane) chooseMapNodeByLane();

  resample(total);  // Eq. 11
  if (bias_state) swapLanes(obs);
  const bool moved =
      params_.lane_evidence_sweeps > 0 && params_.isLaneEvidence(obs.sensor) && moveTowardsLaneEvidence();
  addNoise();   // Eq. 12, leaves the particle counts per node in node_scratch_b_ / touched_
  if (moved) {  // the belief is the moved particles' (the weights above were those before the moves)
    recordBelief(true);
    return overlap;
  }
  // Entropy of the resampled particles (Alg. 1 l. 12).
  const double inv_n = 1.0 / static_cast<double>(particles_.size());
  double h = 0.0;
  for (NodeIndex n : touched_) {
    const double q = mass[n] * inv_n;
    h -= q * std::log(q);
    mass[n] = 0.0;
  }
  belief_.entropy = h;
  belief_.particle_count = particles_.size();
  return overlap;
}

void TopologicalParticleFilter::weighWithBiasState(const core::Observation& obs) {
  // Rao-Blackwellised GNSS update (tpf_params.h, gnss_bias_state). Per axis and particle: the raw fix
  // z = p(q) + b + e, e ~ N(0, R), R = gnss_bias_fix_std^2 + spacing^2 / 12. The device model (gnss_ingest,
  // carried by the fix) says b ~ N(m, P) (m = bias_removed: 0, or the estimate after a sighting; P per axis
  // from bias_covariance) and that b wanders at Q = bias_drift_rate (2 drift_std^2 / drift_tau). b is the
  // Gauss-Markov process with that stationary law and that initial rate, correlation time T = 2 P / Q:
  //   predict  b <- m + a (b - m),  var <- a^2 var + (1 - a^2) P,  a = exp(-dt / T)
  // then weigh by N(z - p - b; 0, S I), S = var + R (normalised: particles with different variances compete
  // fairly), update b += K (z - p - b), var = (1 - K) var, K = var / S.
  // Why mean-reverting and not a random walk (what we had): with a random walk capped at P every particle
  // forgets the prior within minutes, a lane 1.5 m from the truth explains the fixes exactly as well as the
  // right one (its bias simply 1.5 m larger), and which lane the particles settle in is left to resampling
  // noise: pickers held in a wrong lane for a whole walk, where the raw fix was right 75 % of the time. The
  // stationary prior keeps weighing the bias each lane implies against the device's known error size at
  // every fix, so the lane closer to the fixes keeps its evidence unless the motion (lane changes) says
  // otherwise.
  const Eigen::Vector2d raw = *obs.position + *obs.bias_removed;
  const double prior_variance = std::max(0.5 * obs.bias_covariance.trace(), 0.0);
  const double dt = std::max(0.0, obs.stamp - bias_stamp_);
  bias_step_ = bias_stamp_ > 0.0 ? dt : 0.0;
  bias_stamp_ = std::max(bias_stamp_, obs.stamp);
  // a = 1 (no reversion, no growth) for a device without drift or without a prior.
  const double decay = obs.bias_drift_rate > 0.0 && prior_variance > 0.0
                           ? std::exp(-dt * obs.bias_drift_rate / (2.0 * prior_variance))
                           : 1.0;
  const double r = bias_fix_variance_;
  const double prior_x = obs.bias_removed->x(), prior_y = obs.bias_removed->y();
  bias_prior_mean_ = *obs.bias_removed;
  bias_prior_variance_ = prior_variance;
  bias_drift_rate_ = obs.bias_drift_rate;
  const float forget = static_cast<float>(std::exp(-dt / params_.lane_swap_memory)),
              step = static_cast<float>(dt);
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    Particle& p = particles_[i];
    double var, bx, by;
    if (p.bias_variance < 0.0f) {
      bx = prior_x;
      by = prior_y;
      var = prior_variance;
      p.bias_integral_x = p.bias_integral_y = p.bias_time = 0.0f;
    } else {
      bx = prior_x + decay * (p.bias_x - prior_x);
      by = prior_y + decay * (p.bias_y - prior_y);
      var = decay * decay * p.bias_variance + (1.0 - decay * decay) * prior_variance;
    }
    const Eigen::Vector2d node = map_->position2d(p.node);
    const double yx = raw.x() - node.x() - bx, yy = raw.y() - node.y() - by;
    const double s = var + r, k = var / s;
    const double log_density = -0.5 * (yx * yx + yy * yy) / s - std::log(s);
    weights_[i] = log_density;
    best = std::max(best, log_density);
    p.bias_x = static_cast<float>(bx + k * yx);
    p.bias_y = static_cast<float>(by + k * yy);
    p.bias_variance = static_cast<float>(var * r / s);
    p.bias_integral_x = forget * p.bias_integral_x + step * static_cast<float>(p.bias_x - prior_x);
    p.bias_integral_y = forget * p.bias_integral_y + step * static_cast<float>(p.bias_y - prior_y);
    p.bias_time = forget * p.bias_time + step;
  }
  for (double& w : weights_) w = std::exp(w - best);
}

void TopologicalParticleFilter::swapLanes(const core::Observation& obs) {
  // Metropolis-Hastings move (tpf_params.h, lane_swap_rate): a particle at lane node n with bias b proposes
  // the nearest node n' of the adjacent lane on a side drawn at random, with bias b' = b + p(n) - p(n'),
  // which predicts every fix as b did; accepted with min(1, N(b'; m, P) / N(b; m, P)), the device prior of
  // the fix. The proposal is symmetric where the lanes' nodes face each other (evenly spaced parallel lanes);
  // where they are staggered it is nearly so.
  // The device prior is the fix's own: weighWithBiasState() stored it for this observation.
  const SwapPrior prior = swapPrior();
  if (bias_step_ <= 0.0 || !prior.known() || !swapsRun(obs)) return;
  const double propose = -std::expm1(-params_.lane_swap_rate * bias_step_);
  if (!(propose > 0.0)) return;
  std::geometric_distribution<std::size_t> gap(std::min(propose, 1.0));
  for (std::size_t i = gap(rng_); i < particles_.size(); i += 1 + gap(rng_)) {
    Particle& p = particles_[i];
    if (p.bias_variance < 0.0f || p.lane_change != 0) continue;
    const NodeIndex to = graph_->across[2 * p.node + (rng_() & 1u)];
    if (to == topology::kInvalidNode) continue;
    const Eigen::Vector2d shift = map_->position2d(p.node) - map_->position2d(to);
    const double log_ratio = swapLogPriorRatio(p, shift, prior);
    if (log_ratio < 0.0 && uniform01(rng_) >= std::exp(log_ratio)) continue;
    applySwap(p, to, shift);
  }
}

bool TopologicalParticleFilter::swapsRun(const core::Observation& obs) const {
  if (graph_->across.empty() || !(params_.lane_swap_rate > 0.0)) return false;
  // Another sensor (a robot's LiDAR, RFID, UWB) told the lane recently: that evidence is not in the bias path
  // the acceptance weighs, so swaps would undo it (measured: Table II rows with robot sensing lost
  // 0.08-0.10).
  return !(obs.stamp - other_sensor_stamp_ < params_.lane_swap_memory);
}

NodeIndex TopologicalParticleFilter::nextAcross(NodeIndex previous, NodeIndex current) const {
  // The next lane in the same direction: the swap neighbour of `current` away from `previous`.
  const Eigen::Vector2d at = map_->position2d(current), step = at - map_->position2d(previous);
  NodeIndex next = topology::kInvalidNode;
  for (int s = 0; s < 2; ++s) {
    const NodeIndex candidate = graph_->across[2 * current + s];
    if (candidate != topology::kInvalidNode && candidate != previous &&
        (map_->position2d(candidate) - at).dot(step) > 0.0)
      next = candidate;
  }
  return next;
}

template <typename Deposit>
void TopologicalParticleFilter::shareOverLanes(const Particle& p, double weight, const SwapPrior& prior,
                                               Deposit&& deposit) const {
  // Rao-Blackwellisation over the lane (TpfParams::lane_masses_by_swap_prior): given the particle's
  // along-lane place and its bias path, the same walk in any other lane explains every fix alike (its bias
  // shifted by the lanes' offset), so the conditional law of its lane is the device prior's density of each
  // shifted bias and path, normalised over the lanes across from it. The expected mass replaces the
  // particle's draw of it. Every lane across counts, not only the adjacent ones: with the adjacent ones only,
  // a middle lane gathers mass from both sides and an outer lane from one, and the decision leaned inwards
  // (measured).
  const NodeIndex n = p.node;
  if (p.lane_change != 0 || p.bias_variance < 0.0f) {
    deposit(n, weight);
    return;
  }
  constexpr int kMaxLanesPerSide = 12;
  constexpr double kNegligibleLogRatio = -12.0;
  std::array<std::pair<NodeIndex, double>, 2 * kMaxLanesPerSide> across_lanes;
  std::size_t count = 0;
  double sum = 1.0;
  const Eigen::Vector2d here = map_->position2d(n);
  for (int side = 0; side < 2; ++side) {
    NodeIndex previous = n, current = graph_->across[2 * n + side];
    for (int k = 0; k < kMaxLanesPerSide && current != topology::kInvalidNode; ++k) {
      const Eigen::Vector2d at = map_->position2d(current);
      const double log_ratio = swapLogPriorRatio(p, here - at, prior);
      if (log_ratio < kNegligibleLogRatio && k > 0) break;
      const double ratio = std::exp(std::min(log_ratio, 50.0));
      across_lanes[count++] = {current, ratio};
      sum += ratio;
      const NodeIndex next = nextAcross(previous, current);
      previous = current;
      current = next;
    }
  }
  const double scale = weight / sum;
  deposit(n, scale);
  for (std::size_t k = 0; k < count; ++k) deposit(across_lanes[k].first, scale * across_lanes[k].second);
}

TopologicalParticleFilter::SwapPrior TopologicalParticleFilter::swapPrior() const {
  SwapPrior prior;
  if (!(bias_prior_variance_ > 1e-6)) return prior;  // no fix with a prior yet
  prior.mean = bias_prior_mean_;
  prior.inv_two_p = 0.5 / bias_prior_variance_;
  // Path term: shifting the whole recent bias path by d changes the Gauss-Markov path density by
  // -(2 d.A + |d|^2 T) / (4 P tau), A = integral of (b - m) dt, T = integral of dt, tau = 2 P / Q.
  if (bias_drift_rate_ > 0.0)
    prior.inv_four_p_tau = bias_drift_rate_ / (8.0 * bias_prior_variance_ * bias_prior_variance_);
  return prior;
}

double TopologicalParticleFilter::swapLogPriorRatio(const Particle& p, const Eigen::Vector2d& shift,
                                                    const SwapPrior& prior) const {
  const Eigen::Vector2d b(p.bias_x, p.bias_y), moved = b + shift;
  const Eigen::Vector2d integral(p.bias_integral_x, p.bias_integral_y);
  return ((b - prior.mean).squaredNorm() - (moved - prior.mean).squaredNorm()) * prior.inv_two_p -
         (2.0 * shift.dot(integral) + shift.squaredNorm() * p.bias_time) * prior.inv_four_p_tau;
}

void TopologicalParticleFilter::applySwap(Particle& p, NodeIndex to, const Eigen::Vector2d& shift) {
  p.node = to;
  if (p.bias_variance >= 0.0f) {
    p.bias_x = static_cast<float>(p.bias_x + shift.x());
    p.bias_y = static_cast<float>(p.bias_y + shift.y());
    p.bias_integral_x += static_cast<float>(shift.x() * p.bias_time);
    p.bias_integral_y += static_cast<float>(shift.y() * p.bias_time);
  }
  // Velocity, dwell and side memory stay: the hypothesis is the same walk one lane over.
}

bool TopologicalParticleFilter::moveTowardsLaneEvidence() {
  // Resample-move (Gilks and Berzuini 2001; tpf_params.h, lane_evidence_sensors): the particles stand for the
  // posterior after weighting; each sweep proposes the swap move for every particle and accepts with
  // min(1, L(n') / L(n) x the device prior ratio), which leaves the posterior invariant and carries mass into
  // a lane no particle held. L is node_scratch_a_ (the observation's likelihood, 0 off its nodes).
  if (graph_->across.empty()) return false;
  const SwapPrior prior = swapPrior();
  bool moved = false;
  for (int sweep = 0; sweep < params_.lane_evidence_sweeps; ++sweep)
    for (Particle& p : particles_) {
      if (p.lane_change != 0) continue;
      const NodeIndex to = graph_->across[2 * p.node + (rng_() & 1u)];
      if (to == topology::kInvalidNode) continue;
      const double l_from = node_scratch_a_[p.node], l_to = node_scratch_a_[to];
      if (!(l_to > 0.0)) continue;
      const Eigen::Vector2d shift = map_->position2d(p.node) - map_->position2d(to);
      double log_ratio = l_from > 0.0 ? std::log(l_to / l_from) : std::numeric_limits<double>::infinity();
      if (prior.known() && p.bias_variance >= 0.0f) log_ratio += swapLogPriorRatio(p, shift, prior);
      if (log_ratio < 0.0 && uniform01(rng_) >= std::exp(log_ratio)) continue;
      applySwap(p, to, shift);
      moved = true;
    }
  return moved;
}

std::size_t TopologicalParticleFilter::projectOntoLaneEvidence(double max_likelihood) {
  // TpfParams::lane_evidence_projection. node_scratch_a_ holds L (0 off the observation's nodes). A particle
  // whose L is below the max moves with probability 1 - L / max L to the nearest node, in lanes crossed
  // through the swap neighbours on either side, whose L is the max (fewer lanes crossed first; a tie is
  // broken at random), its bias shifted as a swap shifts it. Particles on a lane-change path, off the lanes
  // or with no such node within kMaxLanes lanes stay.
  if (graph_->across.empty()) return 0;
  constexpr int kMaxLanes = 24;
  std::size_t moved = 0;
  for (Particle& p : particles_) {
    const double l = node_scratch_a_[p.node];
    if (p.lane_change != 0 || !(l < max_likelihood) || uniform01(rng_) < l / max_likelihood) continue;
    std::array<NodeIndex, 2> found{topology::kInvalidNode, topology::kInvalidNode};
    std::array<int, 2> lanes_crossed{kMaxLanes + 1, kMaxLanes + 1};
    for (int side = 0; side < 2; ++side) {
      NodeIndex previous = p.node, current = graph_->across[2 * p.node + side];
      for (int k = 1; k <= kMaxLanes && current != topology::kInvalidNode; ++k) {
        if (node_scratch_a_[current] >= max_likelihood) {
          found[side] = current;
          lanes_crossed[side] = k;
          break;
        }
        const NodeIndex next = nextAcross(previous, current);
        previous = current;
        current = next;
      }
    }
    int side = lanes_crossed[0] < lanes_crossed[1] ? 0 : 1;
    if (lanes_crossed[0] == lanes_crossed[1]) side = static_cast<int>(rng_() & 1u);
    const NodeIndex to = found[side];
    if (to == topology::kInvalidNode) continue;
    applySwap(p, to, map_->position2d(p.node) - map_->position2d(to));
    ++moved;
  }
  return moved;
}

void TopologicalParticleFilter::resample(double total) {
  const std::size_t n = particles_.size();
  if (params_.resampling == ResamplingScheme::kLowVariance) {
    const double step = total / static_cast<double>(n);
    double target = uniform01(rng_) * step;
    double acc = weights_[0];
    std::size_t j = 0;
    for (std::size_t i = 0; i < n; ++i) {
      while (acc <= target && j + 1 < n) acc += weights_[++j];
      resampled_[i] = particles_[j];
      target += step;
    }
  } else {
    // Multinomial: cumulative weights and n independent draws (binary search).
    std::vector<double>& cumulative = weights_;
    double acc = 0.0;
    for (double& w : cumulative) w = (acc += w);
    for (std::size_t i = 0; i < n; ++i) {
      const double u = uniform01(rng_) * acc;
      std::size_t j = static_cast<std::size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), u) -
                                               cumulative.begin());
      resampled_[i] = particles_[std::min(j, n - 1)];
    }
  }
  particles_.swap(resampled_);
}

void TopologicalParticleFilter::addNoise() {
  // Eq. 12: q ~ U(N) with probability p_rj, v += N(mu_noise, sigma^2_noise), tau += U(tau^-, tau^+) (tau >=
  // 0).
  if (unconnected_p_ > 0.0) {
    // Which particles jump: geometric gaps between jumping particles (same law as one Bernoulli draw each).
    std::geometric_distribution<std::size_t> gap(unconnected_p_);
    const std::size_t n_nodes = map_->numNodes();
    for (std::size_t i = gap(rng_); i < particles_.size(); i += 1 + gap(rng_)) {
      particles_[i].node = static_cast<NodeIndex>(rng_() % n_nodes);
      particles_[i].dwell = 0.0f;
      particles_[i].lane_change = 0;
      particles_[i].bias_variance = -1.0f;
    }
  }
  // The 32 spare random bits of each particle's prediction draw (spare_bits_, see normalTable()). The
  // velocity is left alone by the fixed-lambda model, which neither uses nor estimates it. The same pass
  // counts the particles per node (node_scratch_b_, touched_) for the entropy.
  const float sigma = static_cast<float>(std::sqrt(params_.velocity_noise_variance));
  const float mu = static_cast<float>(params_.velocity_noise_mean);
  const float lo = static_cast<float>(params_.dwell_noise_min);
  const float step = static_cast<float>((params_.dwell_noise_max - params_.dwell_noise_min) / 255.0);
  const float* normal = normalTable().data();
  constexpr std::uint32_t kMask = (1u << kNormalTableBits) - 1u;
  const bool velocity = params_.motion_model == MotionModel::kVelocity;
  std::vector<double>& count = node_scratch_b_;
  touched_.clear();
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    Particle& p = particles_[i];
    const std::uint32_t r = spare_bits_[i];
    if (velocity) {
      p.vx += mu + sigma * normal[r & kMask];
      p.vy += mu + sigma * normal[(r >> kNormalTableBits) & kMask];
    }
    p.dwell = std::max(0.0f, p.dwell + lo + step * static_cast<float>(r >> 24));
    if (count[p.node] == 0.0) touched_.push_back(p.node);
    count[p.node] += 1.0;
  }
}

void TopologicalParticleFilter::recordBelief(bool counted) {
  // Belief from the particles alone (equal weights): after a prediction, or when weighting was skipped.
  // counted: node_scratch_b_ / touched_ already hold the particle counts (left by predict()).
  std::vector<double>& count = node_scratch_b_;
  if (!counted) {
    touched_.clear();
    for (const Particle& p : particles_) {
      if (count[p.node] == 0.0) touched_.push_back(p.node);
      count[p.node] += 1.0;
    }
  }
  std::sort(touched_.begin(), touched_.end());
  const double inv_n = 1.0 / static_cast<double>(particles_.size());
  belief_.nodes.assign(touched_.begin(), touched_.end());
  belief_.masses.resize(touched_.size());
  double best = -1.0, h = 0.0;
  for (std::size_t k = 0; k < touched_.size(); ++k) {
    const double q = count[touched_[k]] * inv_n;
    belief_.masses[k] = q;
    h -= q * std::log(q);
    if (q > best) {
      best = q;
      belief_.map_node = touched_[k];
    }
    count[touched_[k]] = 0.0;
  }
  if (params_.map_node_by_lane) chooseMapNodeByLane();
  belief_.entropy = h;
  belief_.particle_count = particles_.size();
}

void TopologicalParticleFilter::chooseMapNodeByLane() {
  // TpfParams::map_node_by_lane, coarse to fine: in a lane or not (the totals), then the lane of most mass
  // and its node of most mass, or else the off-lane node of most mass. Comparing one off-lane node with each
  // lane instead favoured a headland node whenever the lanes' mass was spread over several lanes (GNSS only,
  // the Rao-Blackwellised masses): a picker stopped a few metres into a lane was named in the headland. Ties
  // go to the lowest node index (as Eq. 10 here). O(support).
  std::vector<double>& lane_mass = lane_scratch_;
  if (lane_mass.empty() || belief_.nodes.empty()) return;
  double in_lanes = 0.0, off_lanes = 0.0;
  for (std::size_t k = 0; k < belief_.nodes.size(); ++k) {
    const topology::LaneIndex lane = map_->lane(belief_.nodes[k]);
    if (lane >= 0) {
      lane_mass[static_cast<std::size_t>(lane)] += belief_.masses[k];
      in_lanes += belief_.masses[k];
    } else {
      off_lanes += belief_.masses[k];
    }
  }
  topology::LaneIndex best_lane = topology::kNoLane;
  if (in_lanes >= off_lanes) {
    double best_group = -1.0;
    for (NodeIndex n : belief_.nodes) {
      const topology::LaneIndex lane = map_->lane(n);
      if (lane >= 0 && lane_mass[static_cast<std::size_t>(lane)] > best_group) {
        best_group = lane_mass[static_cast<std::size_t>(lane)];
        best_lane = lane;
      }
    }
  }
  const bool want_lane = best_lane >= 0;
  double best = -1.0;
  NodeIndex best_node = belief_.map_node;
  for (std::size_t k = 0; k < belief_.nodes.size(); ++k) {
    const topology::LaneIndex lane = map_->lane(belief_.nodes[k]);
    const bool candidate = want_lane ? lane == best_lane : lane < 0;
    if (candidate && belief_.masses[k] > best) {
      best = belief_.masses[k];
      best_node = belief_.nodes[k];
    }
  }
  for (NodeIndex n : belief_.nodes) {
    const topology::LaneIndex lane = map_->lane(n);
    if (lane >= 0) lane_mass[static_cast<std::size_t>(lane)] = 0.0;
  }
  belief_.map_node = best_node;
}

// ------------------------------------------------------------------------------------------- what-if ------
TopologicalParticleFilter TopologicalParticleFilter::copyWithSeed(std::uint64_t seed) const {
  TopologicalParticleFilter copy(*this);
  if (seed != 0) {
    copy.rng_.seed(seed);
    copy.seed_ = seed;
  }
  return copy;
}

TopologicalParticleFilter TopologicalParticleFilter::predictedCopy(double seconds, std::uint64_t seed) const {
  TopologicalParticleFilter copy = copyWithSeed(seed);
  if (std::isfinite(seconds) && seconds > 0.0) copy.predictTo(belief_.stamp + seconds);
  return copy;
}

Belief TopologicalParticleFilter::predictAhead(double seconds, std::uint64_t seed) const {
  return predictedCopy(seconds, seed).belief_;
}

Belief TopologicalParticleFilter::posteriorNow(const core::Observation& hypothetical,
                                               UpdateResult* result) const {
  TopologicalParticleFilter copy = *this;
  core::Observation obs = hypothetical;
  obs.stamp = belief_.stamp;
  const UpdateResult r = copy.update(obs);
  if (result) *result = r;
  return copy.belief_;
}

Belief TopologicalParticleFilter::posteriorUnder(const core::Observation& hypothetical, double seconds,
                                                 std::uint64_t seed, UpdateResult* result) const {
  return predictedCopy(seconds, seed).posteriorNow(hypothetical, result);
}

}  // namespace tpf
}  // namespace picker_localisation
