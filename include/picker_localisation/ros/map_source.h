// How nodes get the topological map: the ~map_file parameter when set (else the global /map_file), otherwise the
// latched map topic ~map_topic (else the global /map_topic, else /picker_localisation/topological_map, where
// topological_map_server publishes). The topic may carry either of two types, found from the master:
//   picker_localisation/TopologicalMap  (topological_map_server)
//   std_msgs/String                     a tmap2 document as JSON or YAML (LCAS topological_navigation's map
//                                       manager publishes /topological_map_2 this way)
// Any other type is one FATAL line naming the topic, its type and the two accepted ones.
#pragma once

#include <ros/ros.h>

#include <memory>
#include <string>

#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

// The topic topological_map_server publishes on (latched).
constexpr const char* kMapTopic = "/picker_localisation/topological_map";

// Returns the map, or nullptr after logging one FATAL line (bad file, bad map text, wrong topic type, or no map
// within timeout seconds; timeout <= 0 waits forever). Sim time aware: the wait uses wall time so it cannot
// stall on a paused clock.
std::shared_ptr<const topology::TopologicalMap> obtainMap(ros::NodeHandle& nh, ros::NodeHandle& pnh,
                                                          double timeout = 30.0);

// ~datum_source (auto | file | map) of the nodes that turn WGS84 into map coordinates (gnss_ingest, farm_sim):
// true when the map's own datum (tmap2 meta.datum_*) is to be used: `map`, or `auto` and the map has one.
// Throws std::runtime_error on another value, or `map` for a map without a datum.
bool useMapDatum(const std::string& datum_source, const topology::TopologicalMap& map);

// The map topic obtainMap() reads (~map_topic, /map_topic or kMapTopic), resolved.
std::string mapTopic(ros::NodeHandle& nh, ros::NodeHandle& pnh);

}  // namespace ros_adapter
}  // namespace picker_localisation
