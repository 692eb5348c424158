// dispatcher: answers the pickers' calls for the fleet (see docs/readme/dispatch.md).
#include <ros/ros.h>

#include "picker_localisation/ros/dispatcher_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "dispatcher");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::DispatcherNode node(nh, pnh);
  if (!node.ok()) return 1;
  ros::spin();
  return 0;
}
