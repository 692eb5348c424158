#include "picker_localisation/ros/param_yaml.h"

#include <string>

namespace picker_localisation {
namespace ros_adapter {

namespace {

// XmlRpcValue's accessors are non-const; the public entry point copies once and recursion reads the copy.
YAML::Node convert(XmlRpc::XmlRpcValue& x) {
  switch (x.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return YAML::Node(static_cast<bool>(x));
    case XmlRpc::XmlRpcValue::TypeInt:
      return YAML::Node(static_cast<int>(x));
    case XmlRpc::XmlRpcValue::TypeDouble:
      return YAML::Node(static_cast<double>(x));
    case XmlRpc::XmlRpcValue::TypeString:
      return YAML::Node(static_cast<std::string>(x));
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node n(YAML::NodeType::Sequence);
      for (int i = 0; i < x.size(); ++i) n.push_back(convert(x[i]));
      return n;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      YAML::Node n(YAML::NodeType::Map);
      for (auto it = x.begin(); it != x.end(); ++it) n[it->first] = convert(it->second);
      return n;
    }
    default:
      return YAML::Node();
  }
}

}  // namespace

YAML::Node toYaml(const XmlRpc::XmlRpcValue& value) {
  XmlRpc::XmlRpcValue copy = value;
  return convert(copy);
}

YAML::Node paramsAsYaml(const ros::NodeHandle& nh) {
  YAML::Node merged(YAML::NodeType::Map);
  XmlRpc::XmlRpcValue all;
  if (nh.getParam("", all) && all.getType() == XmlRpc::XmlRpcValue::TypeStruct)
    for (auto it = all.begin(); it != all.end(); ++it) merged[it->first] = toYaml(it->second);
  return merged;
}

bool loadCommonOptions(const ros::NodeHandle& pnh, core::CommonNodeOptions& out) {
  const std::string name = ros::this_node::getName();
  try {
    std::vector<std::string> warnings;
    out = core::CommonNodeOptions::fromYaml(paramsAsYaml(pnh), name, &warnings, out);
    for (const auto& w : warnings) ROS_WARN("%s", w.c_str());
    return true;
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return false;
  }
}

}  // namespace ros_adapter
}  // namespace picker_localisation
