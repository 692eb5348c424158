#include "picker_localisation/ros/camera_detector_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "camera_detector");
  picker_localisation::ros_adapter::CameraDetectorNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  if (!node.ok()) return 1;
  ros::spin();
  return 0;
}
