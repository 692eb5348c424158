// tpf_tracker: every picker's Topological Particle Filter in one node (see
// include/picker_localisation/ros/tpf_tracker_node.h).
#include <ros/ros.h>

#include "picker_localisation/ros/tpf_tracker_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "tpf_tracker");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::TpfTracker tracker(nh, pnh);
  if (!tracker.ok()) return 1;
  ros::spin();
  return 0;
}
