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

const tpf::TopologicalParticleFilter& TpfBeliefSource::predictedFilter(double horizon) {
  // The live filter's version: every update, re-initialisation, prediction or map edit counts.
  const tpf::FilterCounters& c = filter_->counters();
  const std::uint64_t version =
      c.accepted + c.reordered + c.reinitialisations + c.predictions + filter_->belief().observations;
  if (version != cached_version_ || filter_->lastStamp() != cached_stamp_ || &filter_->map() != cached_map_) {
    predicted_.clear();
    cached_version_ = version;
    cached_stamp_ = filter_->lastStamp();
    cached_map_ = &filter_->map();
  }
  constexpr std::size_t kMaxHorizons = 16;  // about 1.6 MB per picker at 1,000 particles
  if (predicted_.size() >= kMaxHorizons && predicted_.count(horizon) == 0) predicted_.clear();
  auto it = predicted_.find(horizon);
  if (it == predicted_.end()) it = predicted_.emplace(horizon, filter_->predictedCopy(horizon, seed_)).first;
  return it->second;
}

NodeMasses TpfBeliefSource::predicted(double horizon) {
  if (!filter_->initialised()) return {};
  return denseMasses(predictedFilter(horizon).belief(), filter_->map().numNodes());
}

NodeMasses TpfBeliefSource::posterior(double horizon, const core::Observation& obs) {
  if (!filter_->initialised()) return {};
  return denseMasses(predictedFilter(horizon).posteriorNow(obs), filter_->map().numNodes());
}

}  // namespace nbs
}  // namespace picker_localisation
