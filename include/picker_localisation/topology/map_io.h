// Loading topological maps from the LCAS file formats. ROS-free (yaml-cpp).
#pragma once

#include "picker_localisation/topology/topological_map.h"

#include <cstddef>
#include <string>

namespace picker_localisation {
namespace topology {

enum class MapFormat { kAuto, kTmap2, kLegacyTmap };

// Largest map text accepted (file or topic): 256 MiB, ~650,000 nodes (a 20,400-node tmap2 is 8 MB; yaml-cpp's
// document is ~20x the text). Larger input, and anything but a regular file, is a MapError, never a hang.
constexpr std::size_t kMaxMapBytes = 256u << 20;

// Loads a map file. kAuto picks the format from the content: a YAML mapping with a `nodes` list is tmap2
// (toponav2: `nodes[].node.{name, pose.position, edges[].{edge_id, node, action}}`, optional `meta.tag`);
// a YAML list of `{meta, node}` documents is the legacy (MongoDB-dump) tmap.
// Throws MapError with a one-line message naming the file, the node and the field on any problem.
TopologicalMap loadMap(const std::string& path, MapFormat format = MapFormat::kAuto);

// Same, from text already in memory; `source` names it in errors.
TopologicalMap parseMap(const std::string& text, const std::string& source, MapFormat format = MapFormat::kAuto);

}  // namespace topology
}  // namespace picker_localisation
