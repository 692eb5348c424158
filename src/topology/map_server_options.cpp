#include "picker_localisation/topology/map_server_options.h"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "picker_localisation/core/option_table.h"

namespace picker_localisation {
namespace topology {

namespace {

const char* kComponent = "topological_map_server";

const core::OptionTable<MapServerOptions>& table() {
  using O = MapServerOptions;
  static const core::OptionTable<O> t =
      core::OptionTable<O>().add("node_scale", &O::node_scale).add("labels", &O::labels);
  return t;
}

}  // namespace

std::string MapServerOptions::validate() const {
  const std::string problem = common.validate();
  if (!problem.empty()) return problem;
  if (!(node_scale > 0.0) || !std::isfinite(node_scale))
    return core::badValue("node_scale", node_scale, "finite and > 0");
  return "";
}

const std::vector<std::string>& MapServerOptions::yamlKeys() {
  return table().keys();
}

MapServerOptions MapServerOptions::fromYaml(const YAML::Node& node, std::vector<std::string>* messages) {
  MapServerOptions o;
  o.common = core::CommonNodeOptions::fromYaml(node, kComponent, messages, o.common);
  table().read(node, kComponent, o);
  // Of the shared keys the server has the map file and the frame (the old names of the frame warn).
  return core::checkOptions(
      o, node, core::joinKeys({yamlKeys(), {"map_file", "map_frame", "frame_id", "fixed_frame"}}), kComponent,
      messages);
}

}  // namespace topology
}  // namespace picker_localisation
