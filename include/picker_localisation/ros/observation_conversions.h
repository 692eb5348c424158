// Observation message <-> core Observation (nodes by name in messages, by index in the core).
#pragma once

#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/PickerInfo.h>
#include <ros/time.h>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"

namespace picker_localisation {
namespace ros_adapter {

// A core stamp (s) as a ROS time; a non-finite or negative stamp is time zero.
ros::Time rosStamp(double seconds);

// The support of a tracker's belief on this map: node indices and their masses as sent, leaving out names
// the map does not have and masses that are not finite or negative (gnss_ingest's association and the
// dispatcher read beliefs so; the consumer normalises).
struct BeliefSupport {
  std::vector<topology::NodeIndex> nodes;
  std::vector<double> masses;
};
BeliefSupport beliefSupport(const picker_localisation::PickerBelief& msg,
                            const topology::TopologicalMap& map);

picker_localisation::Observation toMsg(const core::Observation& obs, const topology::TopologicalMap& map,
                                       const std::string& frame_id = "map");

// A picker of the deployment <-> PickerInfo (tpf_tracker's services and /pickers/registry; no tpf overrides).
picker_localisation::PickerInfo toMsg(const core::PickerConfig& picker);
core::PickerConfig fromMsg(const picker_localisation::PickerInfo& msg);

// Converts a message. Node names not in the map are skipped and counted in *unknown_nodes (when given);
// sizes that differ, non-finite values and the like are left for validateObservation() to report.
core::Observation fromMsg(const picker_localisation::Observation& msg, const topology::TopologicalMap& map,
                    std::size_t* unknown_nodes = nullptr);

}  // namespace ros_adapter
}  // namespace picker_localisation
