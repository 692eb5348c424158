// uwb_ranging: see docs/readme/sensors_ranging.md and config/uwb_ranging.yaml.
#include <ros/ros.h>

#include "picker_localisation/ros/uwb_ranging_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "uwb_ranging");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::UwbRangingNode node(nh, pnh);
  if (!node.ok()) return 1;
  ros::spin();
  return 0;
}
