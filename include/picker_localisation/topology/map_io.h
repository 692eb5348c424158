// Loading topological maps from the LCAS file formats. ROS-free (yaml-cpp).
#pragma once

#include "picker_localisation/topology/topological_map.h"

#include <string>

namespace picker_localisation {
namespace topology {

enum class MapFormat { kAuto, kTmap2, kLegacyTmap };

// Loads a map file. kAuto picks the format from the content: a YAML mapping with a `nodes` list is tmap2
// (toponav2: `nodes[].node.{name, pose.position, edges[].{edge_id, node, action}}`, optional `meta.tag`);
// a YAML list of `{meta, node}` documents is the legacy (MongoDB-dump) tmap.
// Throws MapError with a one-line message naming the file, the node and the field on any problem.
TopologicalMap loadMap(const std::string& path, MapFormat format = MapFormat::kAuto);

// Same, from text already in memory; `source` names it in errors.
TopologicalMap parseMap(const std::string& text, const std::string& source, MapFormat format = MapFormat::kAuto);

}  // namespace topology
}  // namespace picker_localisation
