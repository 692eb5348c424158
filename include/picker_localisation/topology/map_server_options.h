// The topological_map_server node's options: map_file (required) and map_frame of the shared node keys, and
// how the map is drawn. ROS-free, so the config test loads its schema.
#pragma once

#include <string>
#include <vector>

#include "picker_localisation/core/node_options.h"

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace topology {

struct MapServerOptions {
  core::CommonNodeOptions common;  // map_file (tmap2 or legacy tmap; required by the node), map_frame
  double node_scale = 0.35;        // m, size of a node's marker
  bool labels = true;              // node names drawn in rviz

  std::string validate() const;  // "" or "<key> = <value>: must be ..."
  // Throws std::runtime_error naming the key on a bad value; *messages gets one line per unknown key and per
  // deprecated name.
  static MapServerOptions fromYaml(const YAML::Node& node, std::vector<std::string>* messages = nullptr);
  static const std::vector<std::string>& yamlKeys();  // the node's own keys (its page's table)
};

}  // namespace topology
}  // namespace picker_localisation
