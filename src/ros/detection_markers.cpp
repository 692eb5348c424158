#include "picker_localisation/ros/detection_markers.h"

#include <algorithm>

namespace picker_localisation {
namespace ros_adapter {

visualization_msgs::MarkerArray personMarkers(const picker_localisation::PersonDetectionArray& people) {
  visualization_msgs::MarkerArray out;
  visualization_msgs::Marker clear;
  clear.header = people.header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  out.markers.push_back(clear);
  int id = 0;
  for (const auto& d : people.detections) {
    visualization_msgs::Marker body;
    body.header = people.header;
    body.ns = "people";
    body.id = id++;
    body.type = visualization_msgs::Marker::CYLINDER;
    body.action = visualization_msgs::Marker::ADD;
    body.pose.position = d.position;
    body.pose.position.z = 0.85;
    body.pose.orientation.w = 1.0;
    body.scale.x = body.scale.y = 0.45;
    body.scale.z = 1.7;
    const bool camera = d.sensor.find("camera") != std::string::npos;
    const bool lidar = d.sensor.rfind("lidar", 0) == 0;
    body.color.r = camera ? 0.1f : (lidar ? 0.2f : 1.0f);
    body.color.g = camera ? 0.9f : (lidar ? 0.5f : 0.6f);
    body.color.b = camera ? 0.2f : (lidar ? 1.0f : 0.1f);
    body.color.a = static_cast<float>(0.3 + 0.6 * std::clamp(d.confidence, 0.0, 1.0));
    out.markers.push_back(body);
    visualization_msgs::Marker label = body;
    label.ns = "people_labels";
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    label.pose.position.z = 1.9;
    label.scale.x = label.scale.y = 0.0;
    label.scale.z = 0.35;
    label.color.r = label.color.g = label.color.b = label.color.a = 1.0f;
    label.text = (d.track_id >= 0 ? "#" + std::to_string(d.track_id) + " " : std::string()) + d.sensor;
    out.markers.push_back(label);
  }
  return out;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
