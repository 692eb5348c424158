// What the Next-Best-Sense planner needs to know about one picker: its belief over the map's nodes, that
// belief predicted ahead, and the posterior it would have after a hypothetical observation. In the planner
// this is the Topological Particle Filter's what-if API (TpfBeliefSource in tpf_belief_source.h, the ROS
// node's WhatIf service client); StaticBeliefSource is a motionless belief with an exact Bayes update, the
// fallback when no what-if is available. ROS-free.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace nbs {

// Dense node masses, one per map node, summing to 1.
using NodeMasses = std::vector<double>;

// Shannon entropy of the node masses, nats (as PickerBelief.entropy). Non-positive masses contribute 0.
double entropy(const NodeMasses& masses);

class BeliefSource {
 public:
  virtual ~BeliefSource() = default;
  virtual const std::string& pickerId() const = 0;
  // The MAP node of the current belief (Eq. 10); kInvalidNode when there is no belief yet.
  virtual topology::NodeIndex estimatedNode() const = 0;
  // Node masses predicted `horizon` s (>= 0) ahead of the last update. Empty when no belief is available.
  virtual NodeMasses predicted(double horizon) = 0;
  // Node masses after predicting `horizon` s and fusing the hypothetical observation `obs`; the live belief
  // is untouched. Empty when not available.
  virtual NodeMasses posterior(double horizon, const core::Observation& obs) = 0;
};

// A belief that does not move (predicted(h) is the belief for every h) and fuses an observation by Bayes'
// rule on the node masses: p'(n) ~ p(n) L(n) (L(n) = 0 for nodes the observation does not list). When the
// observation has no support under the belief, the belief is returned unchanged.
class StaticBeliefSource : public BeliefSource {
 public:
  StaticBeliefSource(std::string picker_id, NodeMasses masses);
  const std::string& pickerId() const override { return id_; }
  topology::NodeIndex estimatedNode() const override { return map_node_; }
  NodeMasses predicted(double) override { return masses_; }
  NodeMasses posterior(double horizon, const core::Observation& obs) override;

 private:
  std::string id_;
  NodeMasses masses_;
  topology::NodeIndex map_node_ = topology::kInvalidNode;
};

}  // namespace nbs
}  // namespace picker_localisation
