// ROS adapter of the leg detector (sensors_vision area): LaserScan topic(s) and optionally a PointCloud2 ->
// people in the fixed (map) frame -> PersonDetectionArray on `people` + one non-identifying Observation per
// person on /observations. Fusion with a camera when ~detections_topic is set (Antonucci 2022 Algorithm 4).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <picker_localisation/BearingDetectionArray.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/node_diagnostics.h"

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/ros/stamp_guard.h"
#include "picker_localisation/sensors_vision/cloud3d_person_detector.h"
#include "picker_localisation/sensors_vision/leg_pipeline.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace ros_adapter {

// Empty when the cloud's data agrees with its metadata (sizes, x/y/z FLOAT32 fields inside point_step), else
// the first problem (one line).
std::string cloudProblem(const sensor_msgs::PointCloud2& cloud);

class LegDetectorNode {
 public:
  LegDetectorNode(ros::NodeHandle nh, ros::NodeHandle pnh);
  bool ok() const { return ok_; }

 private:
  void scanCallback(const sensor_msgs::LaserScan::ConstPtr& msg);
  void cloudCallback(const sensor_msgs::PointCloud2::ConstPtr& msg);
  void detectionsCallback(const picker_localisation::BearingDetectionArray::ConstPtr& msg);
  void cameraInfoCallback(const sensor_msgs::CameraInfo::ConstPtr& msg);
  bool lookup(const std::string& target, const std::string& source, const ros::Time& stamp,
              Eigen::Isometry3d& out);
  // Tracks, fuses and publishes the people of one scan / cloud (positions in the fixed frame).
  void publishPeople(const std::string& source_frame, const ros::Time& stamp,
                     const std::vector<vision::PersonCandidate>& people);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);
  // False (counted, throttled warning) for a stamp too far ahead of the clock; resets the time state once when
  // the clock jumped back.
  bool acceptStamp(const ros::Time& stamp, const char* what);

  ros::NodeHandle nh_, pnh_;
  bool ok_ = false;
  std::string fixed_frame_ = "map", robot_id_;
  double tf_timeout_ = 0.1, fusion_max_age_ = 0.5;
  int max_beams_ = 20000;  // ~max_beams: larger scans are dropped (0: any size)
  // Detector, per-sensor-frame trackers and camera fusion: the same core pipeline the offline runner uses.
  std::unique_ptr<vision::LegPipeline> pipeline_;
  vision::Cloud3dPersonDetector cloud_detector_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<MapFollower> map_follower_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  std::vector<ros::Subscriber> subs_;
  ros::Publisher people_pub_, obs_pub_, people_markers_pub_;
  picker_localisation::BearingDetectionArray::ConstPtr last_detections_;
  sensor_msgs::CameraInfo::ConstPtr camera_info_;
  NodeDiagnostics diagnostics_;  // published at 1 Hz (ROS time)
  std::size_t scans_ = 0, empty_scans_ = 0, tf_failures_ = 0, clouds_ = 0, people_ = 0, observations_ = 0,
              negative_observations_ = 0, camera_frames_ = 0, fused_ = 0, bad_clouds_ = 0,
              bad_detections_ = 0, bad_scans_ = 0;
  StampGuard stamp_guard_;
  ros::Time last_input_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
