#include "picker_localisation/core/observation.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_set>

namespace picker_localisation {
namespace core {

double Observation::totalLikelihood() const {
  return std::accumulate(likelihood.begin(), likelihood.end(), 0.0);
}

void setGaussianLikelihood(Observation& obs, const topology::TopologicalMap& map, const Eigen::Vector2d& mean,
                           const Eigen::Matrix2d& covariance, const GaussianLikelihoodOptions& options) {
  obs.nodes.clear();
  obs.likelihood.clear();
  // Regularise: symmetric, eigenvalues >= max(min_sigma^2, 1e-6).
  Eigen::Matrix2d c = 0.5 * (covariance + covariance.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(c);
  Eigen::Vector2d values = eig.eigenvalues();
  const double floor = std::max(options.min_sigma * options.min_sigma, 1e-6);
  for (int i = 0; i < 2; ++i) values[i] = std::isfinite(values[i]) ? std::max(values[i], floor) : floor;
  c = eig.eigenvectors() * values.asDiagonal() * eig.eigenvectors().transpose();
  const Eigen::Matrix2d info = c.inverse();
  const double radius = options.cutoff_sigmas * std::sqrt(values.maxCoeff());
  std::vector<topology::NodeIndex> near = map.nodesWithin(mean, radius);
  if (near.empty()) near.push_back(map.nearestNode(mean));
  std::sort(near.begin(), near.end());
  std::vector<std::pair<double, topology::NodeIndex>> scored;
  scored.reserve(near.size());
  for (topology::NodeIndex n : near) {
    const Eigen::Vector2d d = map.position2d(n) - mean;
    double l = std::exp(-0.5 * d.dot(info * d));
    if (!(l > 0.0)) l = 1e-300;  // the nearest node fallback must stay positive
    scored.push_back({l, n});
  }
  if (options.max_nodes > 0 && scored.size() > options.max_nodes) {
    std::partial_sort(scored.begin(), scored.begin() + static_cast<long>(options.max_nodes), scored.end(),
                      [](const auto& a, const auto& b) {
                        return a.first > b.first || (a.first == b.first && a.second < b.second);
                      });
    scored.resize(options.max_nodes);
    std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  }
  for (const auto& [l, n] : scored) {
    obs.nodes.push_back(n);
    obs.likelihood.push_back(l);
  }
  obs.position = mean;
  obs.position_covariance = c;
}

bool isCovariance2d(const Eigen::Matrix2d& c) {
  if (!c.allFinite() || c(0, 0) < 0.0 || c(1, 1) < 0.0) return false;
  const double scale = std::max(1.0, c.cwiseAbs().maxCoeff());
  return std::abs(c(0, 1) - c(1, 0)) <= 1e-9 * scale && c.determinant() >= -1e-9 * scale * scale;
}

bool normaliseMasses(std::vector<double>& masses) {
  const double peak = masses.empty() ? 0.0 : *std::max_element(masses.begin(), masses.end());
  if (!(peak > 0.0) || !std::isfinite(peak)) return false;
  double total = 0.0;
  for (double& m : masses) total += (m /= peak);
  for (double& m : masses) m /= total;
  return true;
}

std::string validateObservation(const Observation& obs, const topology::TopologicalMap& map) {
  if (obs.nodes.size() != obs.likelihood.size()) return "nodes and likelihood differ in length";
  if (obs.nodes.empty()) return "empty likelihood";
  if (!std::isfinite(obs.stamp)) return "stamp is not finite";
  if (obs.identifying && obs.picker_id.empty()) return "identifying observation without a picker id";
  std::unordered_set<topology::NodeIndex> seen;
  double total = 0.0;
  for (std::size_t i = 0; i < obs.nodes.size(); ++i) {
    if (obs.nodes[i] >= map.numNodes()) return "node index out of range";
    if (!seen.insert(obs.nodes[i]).second) return "node listed twice";
    if (!std::isfinite(obs.likelihood[i]) || obs.likelihood[i] < 0.0)
      return "likelihood is negative or not finite";
    total += obs.likelihood[i];
  }
  if (!(total > 0.0)) return "likelihood sums to zero";
  if (obs.velocity && !obs.velocity->allFinite()) return "velocity is not finite";
  if (!obs.candidate_probabilities.empty()) {
    if (obs.candidate_probabilities.size() != obs.candidate_pickers.size())
      return "candidate_probabilities and candidate_pickers differ in length";
    for (double p : obs.candidate_probabilities)
      if (!(p >= 0.0 && p <= 1.0)) return "a candidate probability is not in [0, 1]";
  }
  if (obs.position && (!obs.position->allFinite() || !obs.position_covariance.allFinite()))
    return "position or its covariance is not finite";
  if (obs.position && !isCovariance2d(obs.position_covariance))
    return "position covariance is not positive semi-definite";
  if (obs.bias_removed) {
    if (!obs.bias_removed->allFinite() || !obs.bias_covariance.allFinite()) return "bias or its covariance is not finite";
    if (!isCovariance2d(obs.bias_covariance)) return "bias covariance is not positive semi-definite";
    if (!obs.position) return "bias without a position";
    if (!std::isfinite(obs.bias_drift_rate) || obs.bias_drift_rate < 0.0)
      return "bias drift rate is negative or not finite";
  }
  return "";
}

void setLikelihoodOverEveryNode(Observation& obs, std::size_t num_nodes) {
  obs.nodes.resize(num_nodes);
  for (std::size_t n = 0; n < num_nodes; ++n) obs.nodes[n] = static_cast<topology::NodeIndex>(n);
  obs.likelihood.assign(num_nodes, 1.0);
}

bool concernsPicker(bool identifying, const std::string& identified,
                    const std::vector<std::string>& candidates, const std::string& picker_id) {
  if (identifying) return identified == picker_id;
  return candidates.empty() || std::find(candidates.begin(), candidates.end(), picker_id) != candidates.end();
}

bool concernsPicker(const Observation& obs, const std::string& picker_id) {
  return concernsPicker(obs.identifying, obs.picker_id, obs.candidate_pickers, picker_id);
}

double associationProbability(const Observation& obs, const std::string& picker_id) {
  if (obs.candidate_probabilities.empty()) return 1.0;
  if (obs.identifying && obs.picker_id != picker_id) return 0.0;
  for (std::size_t i = 0; i < obs.candidate_pickers.size() && i < obs.candidate_probabilities.size(); ++i)
    if (obs.candidate_pickers[i] == picker_id) return std::clamp(obs.candidate_probabilities[i], 0.0, 1.0);
  return obs.identifying ? 1.0 : 0.0;
}

}  // namespace core
}  // namespace picker_localisation
