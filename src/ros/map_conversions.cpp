#include "picker_localisation/ros/map_conversions.h"

#include <cmath>

namespace picker_localisation {
namespace ros_adapter {

geometry_msgs::Pose nodePose(const topology::Node& node) {
  geometry_msgs::Pose p;
  p.position.x = node.position.x();
  p.position.y = node.position.y();
  p.position.z = node.position.z();
  p.orientation.x = node.orientation[0];
  p.orientation.y = node.orientation[1];
  p.orientation.z = node.orientation[2];
  p.orientation.w = node.orientation[3];
  return p;
}

picker_localisation::TopologicalMap toMsg(const topology::TopologicalMap& map, const std::string& frame_id) {
  picker_localisation::TopologicalMap msg;
  msg.header.frame_id = frame_id;
  msg.name = map.name();
  msg.metric_map = map.metricMap();
  msg.source_file = map.source();
  if (map.datum()) {
    msg.has_datum = true;
    msg.datum_latitude = map.datum()->latitude;
    msg.datum_longitude = map.datum()->longitude;
    msg.datum_altitude = map.datum()->altitude;
  }
  msg.nodes.reserve(map.numNodes());
  for (topology::NodeIndex i = 0; i < map.numNodes(); ++i) {
    picker_localisation::TopologicalNode n;
    n.name = map.node(i).name;
    n.pose = nodePose(map.node(i));
    n.lane = map.laneNameOf(i);
    n.tags = map.node(i).tags;
    msg.nodes.push_back(n);
  }
  for (const topology::Edge& e : map.edges()) {
    picker_localisation::TopologicalEdge m;
    m.edge_id = e.id;
    m.source = e.source;
    m.target = e.target;
    m.action = e.action;
    m.length = e.length;
    msg.edges.push_back(m);
  }
  msg.lanes = map.laneNames();
  return msg;
}

topology::TopologicalMap fromMsg(const picker_localisation::TopologicalMap& msg) {
  std::vector<topology::Node> nodes;
  nodes.reserve(msg.nodes.size());
  for (const auto& m : msg.nodes) {
    topology::Node n;
    n.name = m.name;
    n.position = Eigen::Vector3d(m.pose.position.x, m.pose.position.y, m.pose.position.z);
    n.orientation = {m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z, m.pose.orientation.w};
    n.tags = m.tags;
    // Keep the lane assignment the server made, even when it came from graph structure.
    if (!m.lane.empty() && std::find(n.tags.begin(), n.tags.end(), m.lane) == n.tags.end() &&
        m.lane.rfind("row_", 0) == 0)
      n.tags.push_back(m.lane);
    nodes.push_back(std::move(n));
  }
  std::vector<topology::EdgeSpec> edges;
  for (const auto& e : msg.edges) {
    if (e.source >= msg.nodes.size() || e.target >= msg.nodes.size())
      throw topology::MapError(msg.source_file.empty() ? "<message>" : msg.source_file,
                               "edge '" + e.edge_id + "' has a node index out of range", "", "edges");
    edges.push_back({e.edge_id, msg.nodes[e.source].name, msg.nodes[e.target].name, e.action});
  }
  topology::TopologicalMap map = topology::TopologicalMap::build(
      msg.name, std::move(nodes), edges, msg.source_file.empty() ? "<message>" : msg.source_file, msg.metric_map);
  if (msg.has_datum)  // setDatum throws MapError on a bad latitude / longitude
    map.setDatum(topology::MapDatum{msg.datum_latitude, msg.datum_longitude,
                                    std::isfinite(msg.datum_altitude) ? msg.datum_altitude : 0.0});
  return map;
}

std_msgs::ColorRGBA laneColour(int lane) {
  std_msgs::ColorRGBA c;
  c.a = 1.0;
  if (lane < 0) {
    c.r = c.g = c.b = 0.45f;
    c.a = 0.8f;
    return c;
  }
  // Golden-angle hue walk gives well separated colours for neighbouring lanes.
  const double h = std::fmod(lane * 0.618033988749895, 1.0) * 6.0;
  const double x = 1.0 - std::fabs(std::fmod(h, 2.0) - 1.0);
  double r = 0, g = 0, b = 0;
  switch (static_cast<int>(h)) {
    case 0: r = 1; g = x; break;
    case 1: r = x; g = 1; break;
    case 2: g = 1; b = x; break;
    case 3: g = x; b = 1; break;
    case 4: r = x; b = 1; break;
    default: r = 1; b = x; break;
  }
  // Pale: the lanes stay told apart, and a belief (saturated cyan -> magenta, drawn larger above the nodes)
  // stands out against them at a glance.
  c.r = static_cast<float>(0.55 + 0.3 * r);
  c.g = static_cast<float>(0.55 + 0.3 * g);
  c.b = static_cast<float>(0.55 + 0.3 * b);
  c.a = 0.8f;
  return c;
}

visualization_msgs::MarkerArray mapMarkers(const topology::TopologicalMap& map, const std::string& frame_id,
                                           double node_scale, bool labels) {
  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker nodes;
  nodes.header.frame_id = frame_id;
  nodes.ns = "nodes";
  nodes.id = 0;
  nodes.type = visualization_msgs::Marker::SPHERE_LIST;
  nodes.action = visualization_msgs::Marker::ADD;
  nodes.pose.orientation.w = 1.0;
  nodes.scale.x = nodes.scale.y = nodes.scale.z = node_scale;
  nodes.color.a = 1.0;
  for (topology::NodeIndex i = 0; i < map.numNodes(); ++i) {
    geometry_msgs::Point p;
    p.x = map.node(i).position.x();
    p.y = map.node(i).position.y();
    p.z = map.node(i).position.z();
    nodes.points.push_back(p);
    nodes.colors.push_back(laneColour(map.lane(i)));
  }
  out.markers.push_back(nodes);

  visualization_msgs::Marker edges;
  edges.header.frame_id = frame_id;
  edges.ns = "edges";
  edges.id = 0;
  edges.type = visualization_msgs::Marker::LINE_LIST;
  edges.action = visualization_msgs::Marker::ADD;
  edges.pose.orientation.w = 1.0;
  edges.scale.x = node_scale * 0.2;
  edges.color.r = edges.color.g = edges.color.b = 0.8f;
  edges.color.a = 0.8f;
  for (topology::NodeIndex u = 0; u < map.numNodes(); ++u)
    for (topology::NodeIndex v : map.neighbours(u)) {
      if (v < u) continue;  // one line per undirected edge
      geometry_msgs::Point a, b;
      a.x = map.node(u).position.x();
      a.y = map.node(u).position.y();
      b.x = map.node(v).position.x();
      b.y = map.node(v).position.y();
      edges.points.push_back(a);
      edges.points.push_back(b);
    }
  out.markers.push_back(edges);

  if (labels) {
    for (topology::NodeIndex i = 0; i < map.numNodes(); ++i) {
      visualization_msgs::Marker t;
      t.header.frame_id = frame_id;
      t.ns = "labels";
      t.id = static_cast<int>(i);
      t.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
      t.action = visualization_msgs::Marker::ADD;
      t.pose = nodePose(map.node(i));
      t.pose.orientation = geometry_msgs::Quaternion();
      t.pose.orientation.w = 1.0;
      t.pose.position.z += node_scale * 1.2;
      t.scale.z = node_scale * 0.9;
      t.color.r = t.color.g = t.color.b = 1.0f;
      t.color.a = 0.9f;
      t.text = map.node(i).name;
      out.markers.push_back(t);
    }
  }
  return out;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
