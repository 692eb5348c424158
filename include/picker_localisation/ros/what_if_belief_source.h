// BeliefSource (nbs/belief_source.h) for the nbs_planner node: the pickers' beliefs arrive as PickerBelief
// messages; predictions and hypothetical posteriors come from the tracker's what-if service
// (/pickers/<id>/what_if, picker_localisation/WhatIf: a copy of the live filter, the live one untouched).
// When the service is not available or a call fails, the source falls back to the last published belief used
// as a motionless belief with an exact Bayes update (StaticBeliefSource) and says so (usedFallback()).
#pragma once

#include <ros/ros.h>

#include <picker_localisation/PickerBelief.h>

#include <memory>
#include <string>

#include "picker_localisation/nbs/belief_source.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

// Dense node masses of a PickerBelief message. Node names not in the map and non-finite or negative masses
// are counted in *rejected (when given) and skipped; the rest is renormalised. Empty when nothing valid
// remains.
nbs::NodeMasses massesFromBelief(const picker_localisation::PickerBelief& msg,
                                 const topology::TopologicalMap& map, std::size_t* rejected = nullptr);

class WhatIfBeliefSource : public nbs::BeliefSource {
 public:
  // `client` may be null or not connected (then only the fallback is used). `seed` is sent with every query
  // so the predicted belief and the hypothetical posteriors share the same prediction (common random
  // numbers).
  WhatIfBeliefSource(std::string picker_id, std::shared_ptr<const topology::TopologicalMap> map,
                     const picker_localisation::PickerBelief& belief, ros::ServiceClient* client,
                     std::uint32_t seed, std::string frame_id = "map");
  const std::string& pickerId() const override { return id_; }
  topology::NodeIndex estimatedNode() const override { return estimate_; }
  nbs::NodeMasses predicted(double horizon) override;
  nbs::NodeMasses posterior(double horizon, const core::Observation& obs) override;

  bool usedFallback() const { return used_fallback_; }
  std::size_t calls() const { return calls_; }
  std::size_t failures() const { return failures_; }
  const std::string& lastError() const { return last_error_; }

 private:
  bool query(double horizon, const core::Observation* obs, nbs::NodeMasses& out);

  std::string id_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  nbs::StaticBeliefSource fallback_;
  topology::NodeIndex estimate_;
  ros::ServiceClient* client_;
  std::uint32_t seed_;
  std::string frame_id_;
  bool service_down_ = false;  // after the first failure this plan uses the fallback only
  bool used_fallback_ = false;
  std::size_t calls_ = 0, failures_ = 0;
  std::string last_error_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
