// ROS adapter of the monocular person detector (sensors_vision area): Image + CameraInfo -> person boxes (HOG by
// default, optional ONNX via cv::dnn) -> bearing of each box (Sarmento et al. 2024, Eq. 1) -> BearingDetectionArray on
// `detections` + annotated `debug_image`. Runs at most ~max_rate Hz; frames older than ~max_age are dropped.
#pragma once

#include "picker_localisation/ros/node_diagnostics.h"
#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "picker_localisation/ros/stamp_guard.h"
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <memory>
#include <string>

#include "picker_localisation/sensors_vision/person_box_detector.h"

namespace picker_localisation {
namespace ros_adapter {

class CameraDetectorNode {
 public:
  CameraDetectorNode(ros::NodeHandle nh, ros::NodeHandle pnh);
  bool ok() const { return ok_; }

 private:
  void imageCallback(const sensor_msgs::Image::ConstPtr& msg);
  void infoCallback(const sensor_msgs::CameraInfo::ConstPtr& msg);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::NodeHandle nh_, pnh_;
  bool ok_ = false;
  std::unique_ptr<vision::PersonBoxDetector> detector_;
  std::string robot_id_, bearing_frame_;
  double max_rate_ = 5.0, max_age_ = 0.5, horizontal_fov_ = 0.0;
  ros::Subscriber image_sub_, info_sub_;
  ros::Publisher detections_pub_, debug_pub_;
  sensor_msgs::CameraInfo::ConstPtr info_;
  ros::Time last_processed_;
  NodeDiagnostics diagnostics_;  // published at 1 Hz (ROS time)
  std::size_t received_ = 0, processed_ = 0, dropped_stale_ = 0, dropped_rate_ = 0, dropped_no_info_ = 0,
              bad_images_ = 0, boxes_ = 0;
  StampGuard stamp_guard_;  // future stamps, clock jumping back
  double last_processing_s_ = 0.0;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
