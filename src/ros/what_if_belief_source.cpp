#include "picker_localisation/ros/what_if_belief_source.h"

#include <picker_localisation/WhatIf.h>

#include <algorithm>
#include <cmath>

#include "picker_localisation/ros/observation_conversions.h"

namespace picker_localisation {
namespace ros_adapter {

nbs::NodeMasses massesFromBelief(const picker_localisation::PickerBelief& msg,
                                 const topology::TopologicalMap& map, std::size_t* rejected) {
  nbs::NodeMasses m(map.numNodes(), 0.0);
  double total = 0.0;
  std::size_t bad = msg.nodes.size() != msg.masses.size() ? 1 : 0;
  for (std::size_t k = 0; k < msg.nodes.size() && k < msg.masses.size(); ++k) {
    const auto idx = map.index(msg.nodes[k]);
    const double v = msg.masses[k];
    if (!idx || !std::isfinite(v) || v < 0.0) {
      ++bad;
      continue;
    }
    m[*idx] += v;
    total += v;
  }
  if (rejected) *rejected = bad;
  if (!core::normaliseMasses(m)) return {};
  return m;
}

WhatIfBeliefSource::WhatIfBeliefSource(std::string picker_id,
                                       std::shared_ptr<const topology::TopologicalMap> map,
                                       const picker_localisation::PickerBelief& belief,
                                       ros::ServiceClient* client, std::uint32_t seed, std::string frame_id)
    : id_(std::move(picker_id)),
      map_(std::move(map)),
      fallback_(id_, massesFromBelief(belief, *map_)),
      estimate_(fallback_.estimatedNode()),
      client_(client),
      seed_(seed == 0 ? 1 : seed),
      frame_id_(std::move(frame_id)) {
  // The published MAP node is the tracker's own Eq. 10 estimate; prefer it over the argmax of the masses.
  if (const auto idx = map_->index(belief.estimated_node)) estimate_ = *idx;
}

bool WhatIfBeliefSource::query(double horizon, const core::Observation* obs, nbs::NodeMasses& out) {
  if (!client_ || service_down_) return false;
  picker_localisation::WhatIf srv;
  srv.request.horizon = std::max(0.0, horizon);
  srv.request.with_observation = obs != nullptr;
  if (obs) srv.request.observation = toMsg(*obs, *map_, frame_id_);
  srv.request.seed = seed_;
  ++calls_;
  if (!client_->isValid() || !client_->call(srv)) {
    last_error_ = "what-if service " + client_->getService() + " unavailable";
  } else if (!srv.response.success) {
    last_error_ = "what-if service " + client_->getService() + ": " + srv.response.message;
  } else {
    out = massesFromBelief(srv.response.belief, *map_);
    if (!out.empty()) return true;
    last_error_ = "what-if service " + client_->getService() + " returned an empty belief";
  }
  ++failures_;
  service_down_ = true;
  return false;
}

nbs::NodeMasses WhatIfBeliefSource::predicted(double horizon) {
  nbs::NodeMasses out;
  if (query(horizon, nullptr, out)) return out;
  used_fallback_ = true;
  return fallback_.predicted(horizon);
}

nbs::NodeMasses WhatIfBeliefSource::posterior(double horizon, const core::Observation& obs) {
  nbs::NodeMasses out;
  if (query(horizon, &obs, out)) return out;
  used_fallback_ = true;
  return fallback_.posterior(horizon, obs);
}

}  // namespace ros_adapter
}  // namespace picker_localisation
