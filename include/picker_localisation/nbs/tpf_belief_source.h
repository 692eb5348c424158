// BeliefSource over a live Topological Particle Filter through its what-if API (predictAhead /
// posteriorUnder: copies of the filter, the live one is untouched). Used in-process by the experiment runner
// and the tests. ROS-free.
#pragma once

#include <cstdint>
#include <string>

#include "picker_localisation/nbs/belief_source.h"
#include "picker_localisation/tpf/topological_particle_filter.h"

namespace picker_localisation {
namespace nbs {

// Dense node masses of a TPF belief (empty when the filter is not initialised).
NodeMasses denseMasses(const tpf::Belief& belief, std::size_t num_nodes);

class TpfBeliefSource : public BeliefSource {
 public:
  // `filter` must outlive this object. Every what-if copy is seeded with `seed` (non-zero): the predicted
  // belief and both hypothetical posteriors at one horizon then share the same predicted particles (common
  // random numbers), so their entropy difference carries no prediction noise, and a plan is reproducible.
  TpfBeliefSource(std::string picker_id, const tpf::TopologicalParticleFilter& filter,
                  std::uint64_t seed = 1);
  const std::string& pickerId() const override { return id_; }
  topology::NodeIndex estimatedNode() const override;
  NodeMasses predicted(double horizon) override;
  NodeMasses posterior(double horizon, const core::Observation& obs) override;

 private:
  std::string id_;
  const tpf::TopologicalParticleFilter* filter_;
  std::uint64_t seed_;
};

}  // namespace nbs
}  // namespace picker_localisation
