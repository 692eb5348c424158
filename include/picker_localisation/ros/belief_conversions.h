// A filter's belief as messages: PickerBelief, the MAP estimate as a pose with covariance, and rviz markers
// (the belief over the graph, readable at a glance against the map's lane colours). Used by tpf_tracker.
#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <picker_localisation/PickerBelief.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>

#include "picker_localisation/topology/topological_map.h"
#include "picker_localisation/tpf/topological_particle_filter.h"

namespace picker_localisation {
namespace ros_adapter {

// Messages from a filter's belief (frame_id: map frame).
picker_localisation::PickerBelief toBeliefMsg(const tpf::Belief& belief, const topology::TopologicalMap& map,
                                              const std::string& picker_id, const std::string& frame_id);
geometry_msgs::PoseWithCovarianceStamped toEstimateMsg(const tpf::Belief& belief,
                                                       const topology::TopologicalMap& map,
                                                       const std::string& frame_id);
visualization_msgs::MarkerArray toMarkers(const tpf::Belief& belief, const topology::TopologicalMap& map,
                                          const std::string& picker_id, const std::string& frame_id);

}  // namespace ros_adapter
}  // namespace picker_localisation
