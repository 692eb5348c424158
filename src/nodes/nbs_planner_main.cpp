// nbs_planner: Next-Best-Sense goal planner of one robot (see docs/readme/nbs.md).
#include <ros/ros.h>

#include "picker_localisation/ros/nbs_planner_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "nbs_planner");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::NbsPlannerNode node(nh, pnh);
  if (!node.ok()) return 1;
  ros::spin();
  return 0;
}
