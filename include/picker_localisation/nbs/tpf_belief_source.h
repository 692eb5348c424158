// BeliefSource over a live Topological Particle Filter through its what-if API (predictAhead /
// posteriorUnder: copies of the filter, the live one is untouched). Used in-process by the experiment runner
// and the tests. ROS-free.
#pragma once

#include <cstdint>
#include <map>
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
  // The filter predicted to a horizon, shared by the hypotheses asked at that horizon (one prediction per
  // horizon, as the planner buckets them); dropped when the live filter changed (another update or
  // prediction) and bounded in size, so a long-lived source does not grow.
  const tpf::TopologicalParticleFilter& predictedFilter(double horizon);

  std::string id_;
  const tpf::TopologicalParticleFilter* filter_;
  std::uint64_t seed_;
  std::uint64_t cached_version_ = 0;
  double cached_stamp_ = 0.0;
  const topology::TopologicalMap* cached_map_ = nullptr;
  std::map<double, tpf::TopologicalParticleFilter> predicted_;
};

}  // namespace nbs
}  // namespace picker_localisation
