#include "picker_localisation/ros/belief_conversions.h"

#include "picker_localisation/ros/observation_conversions.h"

#include <algorithm>
#include <cmath>

namespace picker_localisation {
namespace ros_adapter {

namespace {

// Cyan (low) -> magenta (high) for a mass relative to the largest.
std_msgs::ColorRGBA massColour(double relative) {
  std_msgs::ColorRGBA c;
  // Saturated cyan (low mass) -> magenta (the most likely node), against the map's pale lane colours.
  const double r = std::clamp(relative, 0.0, 1.0);
  c.r = static_cast<float>(0.1 + 0.9 * r);
  c.g = static_cast<float>(0.85 * (1.0 - r));
  c.b = 1.0f;
  c.a = static_cast<float>(0.5 + 0.5 * r);
  return c;
}

}  // namespace

picker_localisation::PickerBelief toBeliefMsg(const tpf::Belief& b, const topology::TopologicalMap& map,
                                              const std::string& picker_id, const std::string& frame_id) {
  picker_localisation::PickerBelief m;
  m.header.stamp = rosStamp(b.stamp);
  m.header.frame_id = frame_id;
  m.picker_id = picker_id;
  m.nodes.reserve(b.nodes.size());
  for (auto n : b.nodes) m.nodes.push_back(map.node(n).name);
  m.masses = b.masses;
  if (b.map_node != topology::kInvalidNode && b.map_node < map.numNodes()) {
    const auto& node = map.node(b.map_node);
    m.estimated_node = node.name;
    m.estimated_lane = map.laneNameOf(b.map_node);
    m.estimated_pose.position.x = node.position.x();
    m.estimated_pose.position.y = node.position.y();
    m.estimated_pose.position.z = node.position.z();
    m.estimated_pose.orientation.x = node.orientation[0];
    m.estimated_pose.orientation.y = node.orientation[1];
    m.estimated_pose.orientation.z = node.orientation[2];
    m.estimated_pose.orientation.w = node.orientation[3];
  } else {
    m.estimated_pose.orientation.w = 1.0;
  }
  m.entropy = b.entropy;
  m.jsd = b.jsd;
  m.reinitialised = b.reinitialised;
  m.unconnected_jump_probability = b.unconnected_jump_probability;
  m.particle_count = static_cast<std::uint32_t>(b.particle_count);
  m.observations = static_cast<std::uint32_t>(b.observations);
  return m;
}

geometry_msgs::PoseWithCovarianceStamped toEstimateMsg(const tpf::Belief& b,
                                                       const topology::TopologicalMap& map,
                                                       const std::string& frame_id) {
  geometry_msgs::PoseWithCovarianceStamped m;
  m.header.stamp = rosStamp(b.stamp);
  m.header.frame_id = frame_id;
  m.pose.pose.orientation.w = 1.0;
  if (b.map_node == topology::kInvalidNode || b.map_node >= map.numNodes()) return m;
  const auto& node = map.node(b.map_node);
  m.pose.pose.position.x = node.position.x();
  m.pose.pose.position.y = node.position.y();
  m.pose.pose.position.z = node.position.z();
  m.pose.pose.orientation.x = node.orientation[0];
  m.pose.pose.orientation.y = node.orientation[1];
  m.pose.pose.orientation.z = node.orientation[2];
  m.pose.pose.orientation.w = node.orientation[3];
  // Spread of the belief about the MAP node's position (m^2), mass-weighted; z and rotations unknown.
  const Eigen::Vector2d c = map.position2d(b.map_node);
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (std::size_t k = 0; k < b.nodes.size(); ++k) {
    const Eigen::Vector2d d = map.position2d(b.nodes[k]) - c;
    cov += b.masses[k] * d * d.transpose();
  }
  m.pose.covariance[0] = cov(0, 0);
  m.pose.covariance[1] = cov(0, 1);
  m.pose.covariance[6] = cov(1, 0);
  m.pose.covariance[7] = cov(1, 1);
  m.pose.covariance[14] = 1e6;
  m.pose.covariance[21] = 1e6;
  m.pose.covariance[28] = 1e6;
  m.pose.covariance[35] = 1e6;
  return m;
}

visualization_msgs::MarkerArray toMarkers(const tpf::Belief& b, const topology::TopologicalMap& map,
                                          const std::string& picker_id, const std::string& frame_id) {
  visualization_msgs::MarkerArray arr;
  visualization_msgs::Marker nodes;
  nodes.header.stamp = rosStamp(b.stamp);
  nodes.header.frame_id = frame_id;
  nodes.ns = picker_id + "/belief";
  nodes.id = 0;
  nodes.type = visualization_msgs::Marker::SPHERE_LIST;
  nodes.action = visualization_msgs::Marker::ADD;
  nodes.pose.orientation.w = 1.0;
  nodes.scale.x = nodes.scale.y = nodes.scale.z = 1.1;  // larger than the map's nodes (0.5), drawn above them
  double max_mass = 0.0;
  for (double m : b.masses) max_mass = std::max(max_mass, m);
  for (std::size_t k = 0; k < b.nodes.size(); ++k) {
    geometry_msgs::Point p;
    const auto& pos = map.node(b.nodes[k]).position;
    p.x = pos.x();
    p.y = pos.y();
    p.z = pos.z() + 0.6;
    nodes.points.push_back(p);
    nodes.colors.push_back(massColour(max_mass > 0.0 ? b.masses[k] / max_mass : 0.0));
  }
  if (nodes.points.empty()) nodes.action = visualization_msgs::Marker::DELETE;
  arr.markers.push_back(nodes);

  visualization_msgs::Marker label;
  label.header = nodes.header;
  label.ns = picker_id + "/estimate";
  label.id = 1;
  label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
  label.pose.orientation.w = 1.0;
  label.scale.z = 0.8;
  label.color.r = label.color.g = label.color.b = label.color.a = 1.0f;
  if (b.map_node != topology::kInvalidNode && b.map_node < map.numNodes()) {
    const auto& pos = map.node(b.map_node).position;
    label.action = visualization_msgs::Marker::ADD;
    label.pose.position.x = pos.x();
    label.pose.position.y = pos.y();
    label.pose.position.z = pos.z() + 1.2;
    label.text = picker_id;
  } else {
    label.action = visualization_msgs::Marker::DELETE;
  }
  arr.markers.push_back(label);
  return arr;
}

// One picker's ROS side; its filter, prediction schedule and counters are the fleet's (tpf::TrackerFleet).

}  // namespace ros_adapter
}  // namespace picker_localisation
