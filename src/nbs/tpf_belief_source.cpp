#include "picker_localisation/nbs/tpf_belief_source.h"

namespace picker_localisation {
namespace nbs {

NodeMasses denseMasses(const tpf::Belief& belief, std::size_t num_nodes) {
  if (!belief.initialised || belief.nodes.empty()) return {};
  NodeMasses m(num_nodes, 0.0);
  for (std::size_t k = 0; k < belief.nodes.size() && k < belief.masses.size(); ++k)
    if (belief.nodes[k] < num_nodes) m[belief.nodes[k]] += belief.masses[k];
  return m;
}

TpfBeliefSource::TpfBeliefSource(std::string picker_id, const tpf::TopologicalParticleFilter& filter,
                                 std::uint64_t seed)
    : id_(std::move(picker_id)), filter_(&filter), seed_(seed == 0 ? 1 : seed) {}

topology::NodeIndex TpfBeliefSource::estimatedNode() const {
  return filter_->initialised() ? filter_->belief().map_node : topology::kInvalidNode;
}

NodeMasses TpfBeliefSource::predicted(double horizon) {
  if (!filter_->initialised()) return {};
  return denseMasses(filter_->predictAhead(horizon, seed_), filter_->map().numNodes());
}

NodeMasses TpfBeliefSource::posterior(double horizon, const core::Observation& obs) {
  if (!filter_->initialised()) return {};
  return denseMasses(filter_->posteriorUnder(obs, horizon, seed_), filter_->map().numNodes());
}

}  // namespace nbs
}  // namespace picker_localisation
