// farm_sim: simulated farm (pickers, GNSS, robots, sensors) driving /clock. See docs/readme/sim.md.
#include "picker_localisation/ros/farm_sim_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "farm_sim");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::FarmSimNode node(nh, pnh);
  if (!node.ok()) return 1;
  node.run();
  return 0;
}
