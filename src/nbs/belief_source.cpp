#include "picker_localisation/nbs/belief_source.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace picker_localisation {
namespace nbs {

double entropy(const NodeMasses& masses) {
  double h = 0.0;
  for (double p : masses)
    if (p > 0.0) h -= p * std::log(p);
  return h;
}

StaticBeliefSource::StaticBeliefSource(std::string picker_id, NodeMasses masses)
    : id_(std::move(picker_id)), masses_(std::move(masses)) {
  double total = 0.0;
  for (double& m : masses_) {
    if (!std::isfinite(m) || m < 0.0) m = 0.0;
    total += m;
  }
  if (total <= 0.0) {
    masses_.clear();
    return;
  }
  for (double& m : masses_) m /= total;
  map_node_ =
      static_cast<topology::NodeIndex>(std::max_element(masses_.begin(), masses_.end()) - masses_.begin());
}

NodeMasses StaticBeliefSource::posterior(double, const core::Observation& obs) {
  if (masses_.empty()) return {};
  NodeMasses post(masses_.size(), 0.0);
  double total = 0.0;
  for (std::size_t k = 0; k < obs.nodes.size() && k < obs.likelihood.size(); ++k) {
    const topology::NodeIndex n = obs.nodes[k];
    if (n >= post.size()) continue;
    post[n] = masses_[n] * std::max(0.0, obs.likelihood[k]);
    total += post[n];
  }
  if (!(total > 0.0)) return masses_;
  for (double& m : post) m /= total;
  return post;
}

}  // namespace nbs
}  // namespace picker_localisation
