// ROS adapter: load a topological map and publish it latched with its rviz markers.
#pragma once

#include "picker_localisation/ros/node_diagnostics.h"
#include <diagnostic_updater/diagnostic_updater.h>
#include <picker_localisation/GetTopologicalMap.h>
#include <ros/ros.h>

#include <memory>

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
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  bool ok_ = false;
  picker_localisation::TopologicalMap msg_;
  ros::Publisher map_pub_, marker_pub_;
  ros::ServiceServer service_;
  NodeDiagnostics diagnostics_;  // wall time: reports even while a simulated clock is paused
  std::size_t lanes_ = 0, components_ = 0, requests_ = 0;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
