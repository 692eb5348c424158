// gnss_ingest: see docs/readme/sensors_ranging.md and config/gnss_ingest.yaml.
#include <ros/ros.h>

#include "picker_localisation/ros/gnss_ingest_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "gnss_ingest");
  ros::NodeHandle nh, pnh("~");
  picker_localisation::ros_adapter::GnssIngestNode node(nh, pnh);
  if (!node.ok()) return 1;
  ros::spin();
  return 0;
}
