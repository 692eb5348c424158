// topological_map_server: loads a tmap2 / legacy tmap file and publishes it latched (see README).
#include <ros/ros.h>

#include "picker_localisation/ros/topological_map_server_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "topological_map_server");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::TopologicalMapServer server(nh, pnh);
  if (!server.ok()) return 1;
  ros::spin();
  return 0;
}
