#include "picker_localisation/eval/metrics.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace picker_localisation {
namespace eval {

using topology::NodeIndex;

ErrorSample computeError(const topology::TopologicalMap& map, NodeIndex estimated_node,
                         const Eigen::Vector2d& true_position, double stamp, const std::string& picker_id) {
  if (estimated_node >= map.numNodes()) {
    throw std::out_of_range("computeError: estimated node index " + std::to_string(estimated_node) +
                            " not in map '" + map.name() + "'");
  }
  ErrorSample s;
  s.stamp = stamp;
  s.picker_id = picker_id;
  s.estimated_node = estimated_node;
  s.true_position = true_position;
  s.true_node = map.nearestNode(true_position);
  s.euclidean = (map.position2d(estimated_node) - true_position).norm();
  s.topological = map.hopDistance(estimated_node, s.true_node);
  const topology::LaneIndex true_lane = map.lane(s.true_node);
  const topology::LaneIndex est_lane = map.lane(estimated_node);
  s.lane_applicable = true_lane != topology::kNoLane;
  s.in_true_lane = est_lane == true_lane;  // both kNoLane when the truth is outside every lane
  return s;
}

void meanAndStd(const std::vector<double>& values, double& mean, double& stddev) {
  mean = 0.0;
  stddev = 0.0;
  if (values.empty()) return;
  for (double v : values) mean += v;
  mean /= static_cast<double>(values.size());
  if (values.size() < 2) return;
  double ss = 0.0;
  for (double v : values) ss += (v - mean) * (v - mean);
  stddev = std::sqrt(ss / static_cast<double>(values.size() - 1));
}

namespace {
void populationMeanStd(const std::vector<double>& v, double& mean, double& sd) {
  mean = 0.0;
  sd = 0.0;
  if (v.empty()) return;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - mean) * (x - mean);
  sd = std::sqrt(ss / static_cast<double>(v.size()));
}
}  // namespace

RunMetrics summariseRun(const std::vector<ErrorSample>& samples) {
  RunMetrics r;
  r.samples = samples.size();
  std::vector<double> eu, topo;
  eu.reserve(samples.size());
  topo.reserve(samples.size());
  std::size_t right = 0;
  for (const auto& s : samples) {
    eu.push_back(s.euclidean);
    if (s.topological >= 0) {
      topo.push_back(s.topological);
    } else {
      ++r.unreachable;
    }
    if (s.lane_applicable) {
      ++r.lane_samples;
      if (s.in_true_lane) ++right;
    }
  }
  populationMeanStd(eu, r.euclidean_mean, r.euclidean_std);
  populationMeanStd(topo, r.topological_mean, r.topological_std);
  r.right_lane_share = r.lane_samples > 0 ? static_cast<double>(right) / static_cast<double>(r.lane_samples)
                                          : std::numeric_limits<double>::quiet_NaN();
  return r;
}

MethodSummary summariseMethod(const std::string& method, const std::vector<std::vector<ErrorSample>>& runs) {
  MethodSummary m;
  m.method = method;
  m.runs = runs.size();
  std::vector<double> eu_means, topo_means, shares, eu_all, topo_all;
  for (const auto& run : runs) {
    const RunMetrics r = summariseRun(run);
    if (r.samples == 0) continue;
    eu_means.push_back(r.euclidean_mean);
    if (r.samples > r.unreachable) topo_means.push_back(r.topological_mean);
    if (r.lane_samples > 0) shares.push_back(r.right_lane_share);
    for (const auto& s : run) {
      eu_all.push_back(s.euclidean);
      if (s.topological >= 0) topo_all.push_back(s.topological);
    }
  }
  meanAndStd(eu_means, m.euclidean_mean, m.euclidean_std);
  meanAndStd(topo_means, m.topological_mean, m.topological_std);
  double unused = 0.0;
  populationMeanStd(eu_all, unused, m.euclidean_pooled_std);
  populationMeanStd(topo_all, unused, m.topological_pooled_std);
  meanAndStd(shares, m.right_lane_share, m.right_lane_share_std);
  if (shares.empty()) m.right_lane_share = std::numeric_limits<double>::quiet_NaN();
  return m;
}

MethodSummary unavailableMethod(const std::string& method, const std::string& reason) {
  MethodSummary m;
  m.method = method;
  m.available = false;
  m.unavailable_reason = reason;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  m.euclidean_mean = m.euclidean_std = m.euclidean_pooled_std = nan;
  m.topological_mean = m.topological_std = m.topological_pooled_std = nan;
  m.right_lane_share = m.right_lane_share_std = nan;
  return m;
}

}  // namespace eval
}  // namespace picker_localisation
