// Synthetic maps shared by the nbs tests.
#pragma once

#include <memory>

#include "picker_localisation/topology/synthetic_map.h"

namespace picker_localisation {
namespace nbs_test {

// 5 lanes 8 m apart (a 3 m read region never spans two lanes), 10 nodes per lane `node_spacing` m apart; lane
// nodes r<lane>_<k>, headland nodes H<lane> / T<lane>.
inline std::shared_ptr<const topology::TopologicalMap> wideTunnels(double node_spacing = 3.0) {
  topology::PolytunnelSpec spec;
  spec.lanes = 5;
  spec.nodes_per_lane = 10;
  spec.lane_spacing = 8.0;
  spec.node_spacing = node_spacing;
  return std::make_shared<const topology::TopologicalMap>(topology::makePolytunnelMap(spec));
}

}  // namespace nbs_test
}  // namespace picker_localisation
