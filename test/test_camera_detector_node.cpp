// rostest of camera_detector: frame 0 of vtest.avi with hand-set intrinsics; the person labelled by hand at
// columns 500-530 must come out with the bearing atan((c_x - 515) / f_x); stale frames and frames faster than
// ~max_rate are dropped, not queued; a frame without CameraInfo is dropped without killing the node.
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <picker_localisation/BearingDetectionArray.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <opencv2/videoio.hpp>

#include <cmath>
#include <functional>

#include "camera_rostest_util.h"

using vision_test::waitFor;

TEST(CameraDetectorNode, BearingsStaleFramesRateAndMissingInfo) {
  ros::NodeHandle nh;
  vision_test::CameraDetectorRig rig(nh);
  ASSERT_TRUE(rig.connected(30.0));
  auto& received = rig.received;
  auto& image_pub = rig.image_pub;
  auto& info_pub = rig.info_pub;

  cv::VideoCapture cap("/usr/share/doc/opencv-doc/examples/data/vtest.avi");
  cv::Mat frame;
  ASSERT_TRUE(cap.read(frame));
  auto image = [&](const ros::Time& stamp) {
    std_msgs::Header h;
    h.stamp = stamp;
    h.frame_id = "camera_optical";
    return cv_bridge::CvImage(h, "bgr8", frame).toImageMsg();
  };

  // No CameraInfo yet: dropped. Wait for the count before sending the CameraInfo (a frame still queued then
  // would be used).
  std::string no_info;
  ros::Subscriber diag = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& st : m->status)
          for (const auto& kv : st.values)
            if (kv.key == "dropped: no camera info") no_info = kv.value;
      });
  image_pub.publish(image(ros::Time::now()));
  ASSERT_TRUE(waitFor([&] { return no_info == "1"; })) << "dropped: no camera info '" << no_info << "'";
  EXPECT_TRUE(received.empty());

  sensor_msgs::CameraInfo info;
  info.width = 768;
  info.height = 576;
  info.K = {600.0, 0.0, 384.0, 0.0, 600.0, 288.0, 0.0, 0.0, 1.0};
  info_pub.publish(info);
  waitFor([] { return false; }, 0.5);

  const ros::Time t0 = ros::Time::now();
  image_pub.publish(image(t0));
  ASSERT_TRUE(waitFor([&] { return received.size() == 1; }));
  const auto& a = received[0];
  EXPECT_EQ(a.header.stamp, t0);
  EXPECT_EQ(a.header.frame_id, "camera");
  EXPECT_EQ(a.robot_id, "robot_1");
  ASSERT_GE(a.detections.size(), 2u);
  bool found = false;
  for (const auto& d : a.detections) {
    const double u = d.box.x_offset + 0.5 * d.box.width;
    EXPECT_NEAR(d.bearing, std::atan((384.0 - u) / 600.0), 1e-9);
    // Hand-labelled person at columns 500-530 (centre 515): bearing -0.2148 rad (right of the axis).
    if (std::abs(d.bearing - std::atan((384.0 - 515.0) / 600.0)) < 0.03) found = true;
  }
  EXPECT_TRUE(found);

  // Stale (older than max_age = 8 s) and too soon after the last processed frame (< 1 / 5 Hz): both dropped.
  image_pub.publish(image(ros::Time::now() - ros::Duration(10.0)));
  waitFor([] { return false; }, 0.3);
  image_pub.publish(image(t0 + ros::Duration(0.05)));
  waitFor([] { return false; }, 1.5);
  EXPECT_EQ(received.size(), 1u);
  // Frames smaller than the HOG window (crashed OpenCV 4.6) and a frame stamped in 2100 (ros::Duration threw):
  // no crash; tiny frames give no boxes, the future one is dropped.
  for (const cv::Size s : {cv::Size(1, 1), cv::Size(10, 10), cv::Size(128, 64), cv::Size(640, 2)}) {
    std_msgs::Header h;
    h.stamp = ros::Time::now();
    h.frame_id = "camera_optical";
    image_pub.publish(cv_bridge::CvImage(h, "bgr8", cv::Mat(s, CV_8UC3, cv::Scalar::all(90))).toImageMsg());
    waitFor([] { return false; }, 0.3);
  }
  image_pub.publish(image(ros::Time(4102444800.0)));
  waitFor([] { return false; }, 1.0);
  for (std::size_t i = 1; i < received.size(); ++i) EXPECT_TRUE(received[i].detections.empty());
  const std::size_t before = received.size();
  // Alive: a fresh frame is processed.
  image_pub.publish(image(ros::Time::now()));
  ASSERT_TRUE(waitFor([&] { return received.size() == before + 1; }));
  EXPECT_GE(received.back().detections.size(), 2u);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_camera_detector_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
