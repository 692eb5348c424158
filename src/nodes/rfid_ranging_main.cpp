// rfid_ranging: see docs/readme/sensors_ranging.md and config/rfid_ranging.yaml.
#include <ros/ros.h>

#include "picker_localisation/ros/rfid_ranging_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "rfid_ranging");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::RfidRangingNode node(nh, pnh);
  if (!node.ok()) return 1;
  ros::spin();
  return 0;
}
