#include "picker_localisation/ros/map_source.h"

#include <ros/topic.h>

#include "picker_localisation/ros/map_conversions.h"
#include "picker_localisation/topology/map_io.h"

namespace picker_localisation {
namespace ros_adapter {

std::shared_ptr<const topology::TopologicalMap> obtainMap(ros::NodeHandle& nh, ros::NodeHandle& pnh,
                                                          double timeout) {
  std::string map_file;
  if (!pnh.getParam("map_file", map_file)) nh.getParam("/map_file", map_file);
  try {
    if (!map_file.empty()) return std::make_shared<topology::TopologicalMap>(topology::loadMap(map_file));
    const std::string topic = nh.resolveName("topological_map");
    ROS_INFO("%s: waiting for the topological map on %s", ros::this_node::getName().c_str(), topic.c_str());
    ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout > 0 ? timeout : 1e9);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      auto msg = ros::topic::waitForMessage<picker_localisation::TopologicalMap>(topic, nh, ros::Duration(1.0));
      if (msg) return std::make_shared<topology::TopologicalMap>(fromMsg(*msg));
    }
    ROS_FATAL("%s: no topological map on %s within %.0f s and no ~map_file parameter",
              ros::this_node::getName().c_str(), topic.c_str(), timeout);
  } catch (const topology::MapError& e) {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
  }
  return nullptr;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
