// ROS adapter: load a topological map and publish it latched with its rviz markers.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <picker_localisation/GetTopologicalMap.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include "picker_localisation/ros/node_diagnostics.h"

#include <memory>

#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

class TopologicalMapServer {
 public:
  // Reads ~map_file (required), ~frame_id ("map"), ~node_scale (0.35), ~labels (true). Service ~reload
  // (std_srvs/Trigger): reads ~map_file again (the parameter may name another file now) and publishes it, so
  // a map edited while the robot runs reaches every node that follows the topic; a file that cannot be read
  // is refused with the reason, the current map kept.
  TopologicalMapServer(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  bool ok() const { return ok_; }

 private:
  bool serveMap(GetTopologicalMap::Request&, GetTopologicalMap::Response& res);
  bool reload(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res);
  void publish(const topology::TopologicalMap& map);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  bool ok_ = false;
  picker_localisation::TopologicalMap msg_;
  ros::Publisher map_pub_, marker_pub_;
  ros::ServiceServer service_, reload_service_;
  ros::NodeHandle pnh_;
  std::string frame_id_;
  double node_scale_ = 0.35;
  bool labels_ = true;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::size_t reloads_ = 0, reloads_refused_ = 0;
  NodeDiagnostics diagnostics_;  // wall time: reports even while a simulated clock is paused
  std::size_t lanes_ = 0, components_ = 0, requests_ = 0;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
