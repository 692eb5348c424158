// ROS message / bag adapters of the sensors_vision area: LaserScan -> core::LaserScan, and the labelled leg
// bags of leg_tracker's recordings (test/data/leg_tracker) (rosbag C++ API, no master needed).
#pragma once

#include <sensor_msgs/LaserScan.h>

#include <string>
#include <vector>

#include "picker_localisation/sensors_vision/leg_training.h"

namespace picker_localisation {
namespace ros_adapter {

core::LaserScan toScanData(const sensor_msgs::LaserScan& msg);

struct BagScan {
  std::string topic;
  std::string frame_id;
  core::LaserScan scan;
};

// Every sensor_msgs/LaserScan in the bag, in recording order; `topics` empty: all LaserScan topics.
// Throws rosbag::BagException when the file cannot be opened.
std::vector<BagScan> readBagScans(const std::string& bag_path, const std::vector<std::string>& topics = {});

// A leg_tracker "positive_N_extracted" bag: the k-th /leg_cluster_positions PoseArray labels the k-th
// /training_scan (both are written as one pair per scan by the extraction tool).
std::vector<vision::LabelledScan> readLabelledLegBag(const std::string& bag_path);

}  // namespace ros_adapter
}  // namespace picker_localisation
