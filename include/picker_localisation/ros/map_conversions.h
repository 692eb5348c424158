// Conversions between the core TopologicalMap and ROS messages, and the map's rviz markers.
#pragma once

#include <picker_localisation/TopologicalMap.h>
#include <visualization_msgs/MarkerArray.h>

#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

picker_localisation::TopologicalMap toMsg(const topology::TopologicalMap& map, const std::string& frame_id);
// Rebuilds a core map from the message (edges by index). Throws topology::MapError on inconsistent indices.
topology::TopologicalMap fromMsg(const picker_localisation::TopologicalMap& msg);

// Markers: node spheres (namespace "nodes", coloured by lane), edge lines ("edges", one LINE_LIST) and node
// name labels ("labels"). Stamp left zero so rviz uses the latest tf.
visualization_msgs::MarkerArray mapMarkers(const topology::TopologicalMap& map, const std::string& frame_id,
                                           double node_scale = 0.35, bool labels = true);

// A distinct colour for lane index l (kNoLane: grey).
std_msgs::ColorRGBA laneColour(int lane);

geometry_msgs::Pose nodePose(const topology::Node& node);

}  // namespace ros_adapter
}  // namespace picker_localisation
