// How nodes get the topological map: the ~map_file parameter when set (else the global /map_file), otherwise
// the latched `topological_map` topic of topological_map_server.
#pragma once

#include <ros/ros.h>

#include <memory>

#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

// Returns the map, or nullptr after logging one FATAL line (bad file, or no map within timeout seconds;
// timeout <= 0 waits forever). Sim time aware: the wait uses wall time so it cannot stall on a paused clock.
std::shared_ptr<const topology::TopologicalMap> obtainMap(ros::NodeHandle& nh, ros::NodeHandle& pnh,
                                                          double timeout = 30.0);

}  // namespace ros_adapter
}  // namespace picker_localisation
