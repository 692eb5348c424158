#include "picker_localisation/ros/vision_io.h"

#include <geometry_msgs/PoseArray.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <stdexcept>

namespace picker_localisation {
namespace ros_adapter {

core::LaserScan toScanData(const sensor_msgs::LaserScan& msg) {
  core::LaserScan s;
  s.stamp = msg.header.stamp.toSec();
  s.frame_id = msg.header.frame_id;
  s.angle_min = msg.angle_min;
  s.angle_max = msg.angle_max;
  s.angle_increment = msg.angle_increment;
  s.scan_time = msg.scan_time;
  s.range_min = msg.range_min;
  s.range_max = msg.range_max;
  s.ranges = msg.ranges;
  return s;
}

std::vector<BagScan> readBagScans(const std::string& bag_path, const std::vector<std::string>& topics) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::vector<BagScan> out;
  auto read = [&](rosbag::View& view) {
    for (const auto& m : view) {
      const auto scan = m.instantiate<sensor_msgs::LaserScan>();
      if (!scan) continue;
      out.push_back({m.getTopic(), scan->header.frame_id, toScanData(*scan)});
    }
  };
  if (topics.empty()) {
    rosbag::View view(bag);
    read(view);
  } else {
    rosbag::View view(bag, rosbag::TopicQuery(topics));
    read(view);
  }
  return out;
}

std::vector<vision::LabelledScan> readLabelledLegBag(const std::string& bag_path) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  std::vector<core::LaserScan> scans;
  std::vector<std::vector<Eigen::Vector2d>> labels;
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/training_scan", "/leg_cluster_positions"}));
  for (const auto& m : view) {
    if (const auto scan = m.instantiate<sensor_msgs::LaserScan>()) {
      scans.push_back(toScanData(*scan));
    } else if (const auto poses = m.instantiate<geometry_msgs::PoseArray>()) {
      std::vector<Eigen::Vector2d> legs;
      for (const auto& p : poses->poses) legs.emplace_back(p.position.x, p.position.y);
      labels.push_back(std::move(legs));
    }
  }
  if (scans.size() != labels.size())
    throw std::runtime_error(bag_path + ": " + std::to_string(scans.size()) + " scans but " +
                             std::to_string(labels.size()) + " label arrays");
  std::vector<vision::LabelledScan> out(scans.size());
  for (std::size_t i = 0; i < scans.size(); ++i) out[i] = {std::move(scans[i]), std::move(labels[i])};
  return out;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
