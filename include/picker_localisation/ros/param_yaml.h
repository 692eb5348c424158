// ROS parameter (XmlRpc) -> YAML conversion, so a node can hand its private parameters to a core
// fromYaml() reader (TpfParams, nbs::PlannerConfig, ...).
#pragma once

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>
#include <yaml-cpp/yaml.h>

namespace picker_localisation {
namespace ros_adapter {

// Deep conversion: bool/int/double/string become scalars, arrays sequences, structs maps; any other type
// (invalid, datetime, base64) becomes a null node.
YAML::Node toYaml(const XmlRpc::XmlRpcValue& value);
// Every parameter under the node handle's namespace (a node's private ~ parameters) as one YAML map.
YAML::Node paramsAsYaml(const ros::NodeHandle& nh);

}  // namespace ros_adapter
}  // namespace picker_localisation
