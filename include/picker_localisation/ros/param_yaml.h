// ROS parameter (XmlRpc) -> YAML conversion, so a node can hand its private parameters to a core
// fromYaml() reader (TpfParams, nbs::PlannerConfig, ...).
#pragma once

#include <ros/console.h>
#include <ros/node_handle.h>
#include <ros/this_node.h>
#include <xmlrpcpp/XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

#include <exception>
#include <string>
#include <vector>

#include "picker_localisation/core/node_options.h"

namespace picker_localisation {
namespace ros_adapter {

// Deep conversion: bool/int/double/string become scalars, arrays sequences, structs maps; any other type
// (invalid, datetime, base64) becomes a null node.
YAML::Node toYaml(const XmlRpc::XmlRpcValue& value);
// Every parameter under the node handle's namespace (a node's private ~ parameters) as one YAML map.
YAML::Node paramsAsYaml(const ros::NodeHandle& nh);

// A core options schema (Options::fromYaml(node, &unknown)) from a node's private parameters: one warning per
// unknown key (naming the closest known one); on a bad value one FATAL line naming the key and false.
template <class Options>
bool loadOptions(const ros::NodeHandle& pnh, Options& out) {
  try {
    std::vector<std::string> unknown;
    out = Options::fromYaml(paramsAsYaml(pnh), &unknown);
    for (const auto& u : unknown) ROS_WARN("%s: %s", ros::this_node::getName().c_str(), u.c_str());
    return true;
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    return false;
  }
}

// The keys every node shares (core::CommonNodeOptions) from a node's private parameters, over the node's
// defaults in `out`: one warning per deprecated name; on a bad value one FATAL line naming the key and false.
bool loadCommonOptions(const ros::NodeHandle& pnh, core::CommonNodeOptions& out);

}  // namespace ros_adapter
}  // namespace picker_localisation
