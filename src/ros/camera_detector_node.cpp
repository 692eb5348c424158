#include "picker_localisation/ros/camera_detector_node.h"

#include <cv_bridge/cv_bridge.h>
#include <opencv2/imgproc.hpp>
#include <picker_localisation/BearingDetectionArray.h>

#include <cmath>

#include "picker_localisation/ros/param_yaml.h"

namespace picker_localisation {
namespace ros_adapter {

CameraDetectorNode::CameraDetectorNode(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), diagnostics_(nh, pnh) {
  // One options schema (config/vision.yaml camera_detector section, same keys as the private parameters).
  vision::CameraDetectorOptions o;
  if (!loadOptions(pnh_, o)) return;
  robot_id_ = o.robot_id;
  bearing_frame_ = o.bearing_frame;
  max_rate_ = o.max_rate;
  max_age_ = o.max_age;
  stamp_guard_ = StampGuard(o.max_future_stamp);
  horizontal_fov_ = o.horizontal_fov;
  try {
    detector_ = o.makeDetector();
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    return;
  }
  // Queue of one: while a frame is processed newer ones replace older ones instead of queueing.
  image_sub_ = nh_.subscribe("image", 1, &CameraDetectorNode::imageCallback, this);
  info_sub_ = nh_.subscribe("camera_info", 1, &CameraDetectorNode::infoCallback, this);
  detections_pub_ = nh_.advertise<picker_localisation::BearingDetectionArray>("detections", 10);
  debug_pub_ = nh_.advertise<sensor_msgs::Image>("debug_image", 1);
  diagnostics_.setHardwareID(robot_id_.empty() ? "camera_detector" : robot_id_);
  diagnostics_.add("camera detector", this, &CameraDetectorNode::diagnose);
  diagnostics_.input("images", 5.0);
  diagnostics_.start(nh_);
  ok_ = true;
  ROS_INFO("%s: %s detector, at most %.1f Hz", ros::this_node::getName().c_str(), o.onnx_model.empty() ? "HOG" : "ONNX",
           max_rate_);
}

void CameraDetectorNode::infoCallback(const sensor_msgs::CameraInfo::ConstPtr& msg) { info_ = msg; }

void CameraDetectorNode::imageCallback(const sensor_msgs::Image::ConstPtr& msg) {
  diagnostics_.tick("images");
  ++received_;
  const ros::Time stamp = msg->header.stamp;
  if (stamp_guard_.tooFarInFuture(stamp)) {
    ROS_WARN_THROTTLE(10.0, "%s: frame stamped %.3f is more than %.1f s ahead of the clock: dropped",
                      ros::this_node::getName().c_str(), stamp.toSec(), stamp_guard_.maxFuture());
    return;
  }
  if (stamp_guard_.clockJumpedBack()) {
    ROS_WARN("%s: the clock jumped back: frame-rate state reset", ros::this_node::getName().c_str());
    last_processed_ = ros::Time();
  }
  if (max_age_ > 0.0 && secondsBetween(stamp, ros::Time::now()) > max_age_) {
    ++dropped_stale_;
    ROS_WARN_THROTTLE(10.0, "%s: dropping frames older than %.2f s", ros::this_node::getName().c_str(), max_age_);
    return;
  }
  if (max_rate_ > 0.0 && !last_processed_.isZero() && stamp >= last_processed_ &&
      secondsBetween(last_processed_, stamp) < 1.0 / max_rate_) {
    ++dropped_rate_;
    return;
  }
  vision::CameraIntrinsics k;
  if (info_ && info_->K[0] > 0.0) {
    k = {info_->K[0], info_->K[2], static_cast<int>(info_->width)};
  } else if (horizontal_fov_ > 0.0 && msg->width > 0) {
    // Eq. 1 in its field-of-view form: f_x = (w / 2) / tan(f_w / 2), centre at w / 2.
    k = {0.5 * msg->width / std::tan(0.5 * horizontal_fov_), 0.5 * msg->width, static_cast<int>(msg->width)};
  } else {
    ++dropped_no_info_;
    ROS_WARN_THROTTLE(10.0, "%s: no CameraInfo (and no ~horizontal_fov): frame dropped",
                      ros::this_node::getName().c_str());
    return;
  }
  cv_bridge::CvImageConstPtr cv;
  try {
    cv = cv_bridge::toCvShare(msg, "bgr8");
  } catch (const cv_bridge::Exception& e) {
    ++bad_images_;
    ROS_WARN_THROTTLE(10.0, "%s: cannot convert image (%s): %s", ros::this_node::getName().c_str(),
                      msg->encoding.c_str(), e.what());
    return;
  }
  last_processed_ = stamp;
  const ros::WallTime t0 = ros::WallTime::now();
  const auto boxes = detector_->detect(cv->image);
  last_processing_s_ = (ros::WallTime::now() - t0).toSec();
  ++processed_;

  picker_localisation::BearingDetectionArray out;
  out.header.stamp = stamp;
  out.header.frame_id = bearing_frame_.empty() ? msg->header.frame_id : bearing_frame_;
  out.robot_id = robot_id_;
  for (const auto& b : boxes) {
    picker_localisation::BearingDetection d;
    d.box.x_offset = static_cast<uint32_t>(b.box.x);
    d.box.y_offset = static_cast<uint32_t>(b.box.y);
    d.box.width = static_cast<uint32_t>(b.box.width);
    d.box.height = static_cast<uint32_t>(b.box.height);
    d.bearing = vision::bearingFromBox(b.box, k);
    d.confidence = b.confidence;
    out.detections.push_back(d);
  }
  boxes_ += boxes.size();
  detections_pub_.publish(out);

  if (debug_pub_.getNumSubscribers() > 0) {
    cv_bridge::CvImage debug(msg->header, "bgr8", cv->image.clone());
    for (const auto& d : out.detections) {
      const cv::Rect r(d.box.x_offset, d.box.y_offset, d.box.width, d.box.height);
      cv::rectangle(debug.image, r, cv::Scalar(0, 255, 0), 2);
      char text[64];
      std::snprintf(text, sizeof(text), "%.1f deg %.2f", d.bearing * 180.0 / M_PI, d.confidence);
      cv::putText(debug.image, text, r.tl() + cv::Point(0, -4), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                  cv::Scalar(0, 255, 0), 1);
    }
    debug_pub_.publish(debug.toImageMsg());
  }
}

void CameraDetectorNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  if (received_ == 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no image received yet");
  else if (processed_ == 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "images received but none processed");
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
  stat.add("images received", received_);
  stat.add("images processed", processed_);
  stat.add("dropped: stale", dropped_stale_);
  stat.add("dropped: rate limit", dropped_rate_);
  stat.add("dropped: no camera info", dropped_no_info_);
  stat.add("dropped: bad encoding", bad_images_);
  stat.add("dropped: stamp in the future", stamp_guard_.futureStamps());
  stat.add("boxes published", boxes_);
  stat.add("last processing time (s)", last_processing_s_);
}

}  // namespace ros_adapter
}  // namespace picker_localisation
