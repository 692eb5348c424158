#include "picker_localisation/ros/map_source.h"

#include <ros/master.h>
#include <ros/topic.h>
#include <std_msgs/String.h>

#include <stdexcept>

#include "picker_localisation/ros/map_conversions.h"
#include "picker_localisation/topology/map_io.h"

namespace picker_localisation {
namespace ros_adapter {

std::string mapTopic(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  std::string topic;
  if (!pnh.getParam("map_topic", topic) || topic.empty()) nh.getParam("/map_topic", topic);
  return nh.resolveName(topic.empty() ? std::string(kMapTopic) : topic);
}

bool useMapDatum(const std::string& datum_source, const topology::TopologicalMap& map) {
  if (datum_source != "auto" && datum_source != "file" && datum_source != "map")
    throw std::runtime_error("~datum_source '" + datum_source + "' must be auto, file or map");
  if (datum_source == "map" && !map.datum())
    throw std::runtime_error("~datum_source is map but the map has no meta.datum_latitude");
  return datum_source == "map" || (datum_source == "auto" && map.datum());
}

namespace {

// The type the master knows for `topic` ("" while nobody advertises it).
std::string topicType(const std::string& topic) {
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return "";
  for (const auto& t : topics)
    if (t.name == topic) return t.datatype;
  return "";
}

}  // namespace

std::shared_ptr<const topology::TopologicalMap> obtainMap(ros::NodeHandle& nh, ros::NodeHandle& pnh,
                                                          double timeout) {
  const std::string name = ros::this_node::getName();
  std::string map_file;
  if (!pnh.getParam("map_file", map_file)) nh.getParam("/map_file", map_file);
  try {
    if (!map_file.empty()) return std::make_shared<topology::TopologicalMap>(topology::loadMap(map_file));
    const std::string topic = mapTopic(nh, pnh);
    ROS_INFO("%s: waiting for the topological map on %s", name.c_str(), topic.c_str());
    ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout > 0 ? timeout : 1e9);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      const std::string type = topicType(topic);
      if (type == "picker_localisation/TopologicalMap") {
        auto msg =
            ros::topic::waitForMessage<picker_localisation::TopologicalMap>(topic, nh, ros::Duration(1.0));
        if (msg) return std::make_shared<topology::TopologicalMap>(fromMsg(*msg));
      } else if (type == "std_msgs/String") {
        auto msg = ros::topic::waitForMessage<std_msgs::String>(topic, nh, ros::Duration(1.0));
        if (msg) {
          auto map = std::make_shared<topology::TopologicalMap>(topology::parseMap(msg->data, topic));
          ROS_INFO("%s: map '%s' from %s (tmap2 text): %zu nodes, %zu lanes", name.c_str(),
                   map->name().c_str(), topic.c_str(), map->numNodes(), map->numLanes());
          return map;
        }
      } else if (!type.empty()) {
        ROS_FATAL(
            "%s: %s is a %s; a map topic must be picker_localisation/TopologicalMap (topological_map_server) "
            "or std_msgs/String holding a tmap2 document (LCAS: /topological_map_2)%s",
            name.c_str(), topic.c_str(), type.c_str(),
            type.rfind("topological_navigation_msgs/", 0) == 0 ? "; set map_topic:=/topological_map_2" : "");
        return nullptr;
      } else {
        ros::WallDuration(0.2).sleep();
      }
    }
    ROS_FATAL("%s: no topological map on %s within %.0f s and no ~map_file parameter", name.c_str(),
              topic.c_str(), timeout);
  } catch (const topology::MapError& e) {
    ROS_FATAL("%s: %s", name.c_str(), e.what());
  }
  return nullptr;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
