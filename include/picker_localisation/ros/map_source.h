// How nodes get the topological map: the ~map_file parameter when set (else the global /map_file), otherwise the
// latched map topic ~map_topic (else the global /map_topic, else /picker_localisation/topological_map, where
// topological_map_server publishes). The topic may carry either of two types, found from the master:
//   picker_localisation/TopologicalMap  (topological_map_server)
//   std_msgs/String                     a tmap2 document as JSON or YAML (LCAS topological_navigation's map
//                                       manager publishes /topological_map_2 this way)
// Any other type is one FATAL line naming the topic, its type and the two accepted ones.
#pragma once

#include <ros/ros.h>

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "picker_localisation/core/node_options.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

// The topic topological_map_server publishes on (latched).
constexpr const char* kMapTopic = "/picker_localisation/topological_map";

// Returns the map, or nullptr after logging one FATAL line (bad file, bad map text, wrong topic type, or no
// map within timeout seconds; timeout <= 0 waits forever). Sim time aware: the wait uses wall time so it
// cannot stall on a paused clock. The source: common.map_file, else common.map_topic (each falling back to
// the global /map_file, /map_topic), waiting common.map_timeout s.
std::shared_ptr<const topology::TopologicalMap> obtainMap(ros::NodeHandle& nh,
                                                          const core::CommonNodeOptions& common);
// The map keys of a node without an options struct of its own (farm_sim, evaluator, dispatcher); nullopt
// after one FATAL line on a bad value.
std::optional<core::CommonNodeOptions> mapOptionsOf(const ros::NodeHandle& pnh);

// ~datum_source (auto | file | map) of the nodes that turn WGS84 into map coordinates (gnss_ingest, farm_sim):
// true when the map's own datum (tmap2 meta.datum_*) is to be used: `map`, or `auto` and the map has one.
// Throws std::runtime_error on another value, or `map` for a map without a datum.
bool useMapDatum(const std::string& datum_source, const topology::TopologicalMap& map);

// The map topic obtainMap() reads (map_topic, /map_topic or kMapTopic), resolved.
std::string mapTopic(ros::NodeHandle& nh, const core::CommonNodeOptions& common);

// The map after start-up: a map manager may edit it while the robot runs (LCAS topological_navigation
// re-publishes /topological_map_2; topological_map_server's ~reload). Every node that read its map from the
// topic keeps following it with one MapFollower: a later valid map that differs from the current one is
// handed to `adopt` with how it differs (topology::compareMaps), after one INFO line "<node>: map updated:
// +N -M nodes, K moved"; a message that cannot be read is refused with one ERROR line and diagnostics ERROR
// ("<node>: map"), the current map kept; an identical re-publication (the latched message again) costs one
// comparison. A node given ~map_file (or /map_file) has nothing to follow and never calls `adopt`.
class MapFollower {
 public:
  using Adopt = std::function<void(std::shared_ptr<const topology::TopologicalMap> map,
                                   const topology::MapChange& change)>;
  MapFollower(ros::NodeHandle& nh, const core::CommonNodeOptions& common,
              std::shared_ptr<const topology::TopologicalMap> current, Adopt adopt);
  ~MapFollower();
  MapFollower(const MapFollower&) = delete;
  MapFollower& operator=(const MapFollower&) = delete;
  bool following() const;
  std::size_t updates() const;   // maps adopted
  std::size_t refusals() const;  // messages refused

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
