#include "picker_localisation/ros/topological_map_server_node.h"
#include "picker_localisation/topology/map_server_options.h"

#include <cmath>

#include "picker_localisation/core/yaml_keys.h"
#include "picker_localisation/ros/map_conversions.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/topology/map_io.h"

namespace picker_localisation {
namespace ros_adapter {

TopologicalMapServer::TopologicalMapServer(ros::NodeHandle& nh, ros::NodeHandle& pnh) : pnh_(pnh) {
  topology::MapServerOptions o;
  if (!loadOptions(pnh, o)) return;
  const std::string& map_file = o.common.map_file;
  if (map_file.empty()) {
    ROS_FATAL("topological_map_server: parameter ~map_file is required (a tmap2 or legacy tmap file)");
    return;
  }
  frame_id_ = o.common.map_frame;
  node_scale_ = o.node_scale;
  labels_ = o.labels;
  try {
    const topology::TopologicalMap map = topology::loadMap(map_file);
    // Not /topological_map: LCAS topological_navigation publishes its own type there.
    map_pub_ = nh.advertise<picker_localisation::TopologicalMap>(kMapTopic, 1, /*latch=*/true);
    marker_pub_ = nh.advertise<visualization_msgs::MarkerArray>("topological_map/markers", 1, /*latch=*/true);
    service_ = nh.advertiseService("get_topological_map", &TopologicalMapServer::serveMap, this);
    reload_service_ = pnh.advertiseService("reload", &TopologicalMapServer::reload, this);
    publish(map);
    ROS_INFO("topological_map_server: '%s' from %s: %zu nodes, %zu directed edges, %zu lanes",
             map.name().c_str(), map_file.c_str(), map.numNodes(), map.numDirectedEdges(), map.numLanes());
    diagnostics_.setHardwareID(map_file);
    diagnostics_.add("topological map", this, &TopologicalMapServer::diagnose);
    diagnostics_.start(nh, 1.0, /*wall=*/true);
    ok_ = true;
  } catch (const topology::MapError& e) {
    ROS_FATAL("topological_map_server: %s", e.what());
  }
}

void TopologicalMapServer::publish(const topology::TopologicalMap& map) {
  msg_ = toMsg(map, frame_id_);
  msg_.header.stamp = ros::Time::now();
  msg_.header.seq = static_cast<std::uint32_t>(reloads_);  // a new message to the followers' fingerprint
  map_pub_.publish(msg_);
  visualization_msgs::MarkerArray markers = mapMarkers(map, frame_id_, node_scale_, labels_);
  if (reloads_ > 0) {  // rviz keeps the labels of nodes the new map no longer has: clear them first
    visualization_msgs::Marker clear;
    clear.header.frame_id = frame_id_;
    clear.action = visualization_msgs::Marker::DELETEALL;
    markers.markers.insert(markers.markers.begin(), clear);
  }
  marker_pub_.publish(markers);
  lanes_ = map.numLanes();
  components_ = map.numComponents();
  map_ = std::make_shared<topology::TopologicalMap>(map);
}

bool TopologicalMapServer::reload(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  // The parameter as it is now: a map manager may have pointed it at another file.
  std::string map_file;
  pnh_.getParam("map_file", map_file);
  try {
    const topology::TopologicalMap map = topology::loadMap(map_file);
    const topology::MapChange change = topology::compareMaps(*map_, map);
    ++reloads_;
    publish(map);
    res.success = true;
    res.message = "map '" + map.name() + "' from " + map_file + " published: " + change.summary();
    ROS_INFO("topological_map_server: %s", res.message.c_str());
  } catch (const std::exception& e) {
    ++reloads_refused_;
    res.success = false;
    res.message = std::string("not reloaded, the current map stays: ") + e.what();
    ROS_ERROR("topological_map_server: %s", res.message.c_str());
  }
  return true;
}

void TopologicalMapServer::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  // A map split into several components strands pickers: worth a warning, not an error.
  if (components_ > 1)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "map has " + std::to_string(components_) + " components");
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "map loaded");
  stat.add("map", msg_.name);
  stat.add("source file", msg_.source_file);
  stat.add("nodes", msg_.nodes.size());
  stat.add("directed edges", msg_.edges.size());
  stat.add("lanes", lanes_);
  stat.add("components", components_);
  stat.add("service requests", requests_);
  stat.add("reloads / refused", std::to_string(reloads_) + " / " + std::to_string(reloads_refused_));
}

bool TopologicalMapServer::serveMap(GetTopologicalMap::Request&, GetTopologicalMap::Response& res) {
  ++requests_;
  res.map = msg_;
  return true;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
