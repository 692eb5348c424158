#include "picker_localisation/ros/leg_detector_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "leg_detector");
  picker_localisation::ros_adapter::LegDetectorNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.ok()) return 1;
  ros::spin();
  return 0;
}
