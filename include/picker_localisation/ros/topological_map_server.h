// ROS adapter: load a topological map and publish it latched with its rviz markers.
#pragma once

#include <picker_localisation/GetTopologicalMap.h>
#include <ros/ros.h>

#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

class TopologicalMapServer {
 public:
  // Reads ~map_file (required), ~frame_id ("map"), ~node_scale (0.35), ~labels (true).
  TopologicalMapServer(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  bool ok() const { return ok_; }

 private:
  bool serveMap(GetTopologicalMap::Request&, GetTopologicalMap::Response& res);

  bool ok_ = false;
  picker_localisation::TopologicalMap msg_;
  ros::Publisher map_pub_, marker_pub_;
  ros::ServiceServer service_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
