// evaluator: live tracking errors against the simulator's ground truth; prints the error table at shutdown.
#include <ros/ros.h>

#include "picker_localisation/ros/evaluator_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "evaluator");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::Evaluator evaluator(nh, pnh);
  if (!evaluator.ok()) return 1;
  ros::spin();
  evaluator.finish();  // Ctrl-C / roslaunch shutdown: print the table too
  return 0;
}
