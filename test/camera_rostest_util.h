// Shared side of the camera_detector rostests: the detections received, the image and CameraInfo publishers.
#pragma once

#include <picker_localisation/BearingDetectionArray.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <vector>

#include "vision_rostest_util.h"

namespace vision_test {

struct CameraDetectorRig {
  std::vector<picker_localisation::BearingDetectionArray> received;
  ros::Subscriber detections_sub;
  ros::Publisher image_pub, info_pub;

  explicit CameraDetectorRig(ros::NodeHandle& nh) {
    detections_sub = nh.subscribe<picker_localisation::BearingDetectionArray>(
        "detections", 10,
        [this](const picker_localisation::BearingDetectionArray::ConstPtr& m) { received.push_back(*m); });
    image_pub = nh.advertise<sensor_msgs::Image>("image", 5);
    info_pub = nh.advertise<sensor_msgs::CameraInfo>("camera_info", 1, true);
  }
  // True once camera_detector subscribes to the images and the CameraInfo and publishes detections (within
  // `seconds`): a CameraInfo published after that goes over an open connection.
  bool connected(double seconds = kDeadline) {
    return waitFor(
        [this] {
          return image_pub.getNumSubscribers() > 0 && info_pub.getNumSubscribers() > 0 &&
                 detections_sub.getNumPublishers() > 0;
        },
        seconds);
  }
  // Spins until `count` detection arrays have arrived (within `seconds`).
  bool receivedAtLeast(std::size_t count, double seconds = kDeadline) {
    return waitFor([this, count] { return received.size() >= count; }, seconds);
  }
};

}  // namespace vision_test
