// picker_fleet: gnss_ingest and tpf_tracker in one process (one node, "tpf_tracker"), so the fixes' observations
// reach the filters without a socket. Parameters: the tracker's as private parameters (~pickers_file, ...), the
// ingest's under ~gnss_ingest/ (~gnss_ingest/datum_file, ...). Topics and services as the two nodes'.
#include <ros/ros.h>

#include "picker_localisation/ros/gnss_ingest_node.h"
#include "picker_localisation/ros/tpf_tracker_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "tpf_tracker");
  ros::NodeHandle nh, pnh("~"), ingest_pnh("~gnss_ingest");
  picker_localisation::ros_adapter::TpfTracker tracker(nh, pnh);
  if (!tracker.ok()) return 1;
  picker_localisation::ros_adapter::GnssIngestNode ingest(nh, ingest_pnh);
  if (!ingest.ok()) return 1;
  ros::spin();
  return 0;
}
