#include <ros/names.h>
#include <tf2/exceptions.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/ranging_nodes.h"

namespace picker_localisation {
namespace ros_adapter {

sensor_msgs::NavSatFix navSatFixAt(const core::GeodeticDatum& datum, const Eigen::Vector2d& map_xy,
                                   const ros::Time& stamp, double sigma) {
  sensor_msgs::NavSatFix f;
  f.header.stamp = stamp;
  f.header.frame_id = "gps";
  const Eigen::Vector2d ll = datum.toLatLon(map_xy);
  f.latitude = ll.x();
  f.longitude = ll.y();
  f.altitude = 50.0;
  f.status.status = sensor_msgs::NavSatStatus::STATUS_FIX;
  const double v = sigma * sigma;
  f.position_covariance = {v, 0, 0, 0, v, 0, 0, 0, 4.0 * v};
  f.position_covariance_type = sensor_msgs::NavSatFix::COVARIANCE_TYPE_DIAGONAL_KNOWN;
  return f;
}

core::GnssFix gnssFixFromMsg(const sensor_msgs::NavSatFix& msg) {
  core::GnssFix f;
  f.stamp = msg.header.stamp.toSec();
  f.latitude = msg.latitude;
  f.longitude = msg.longitude;
  f.altitude = msg.altitude;
  f.status = msg.status.status;
  for (std::size_t i = 0; i < 9; ++i) f.position_covariance[i] = msg.position_covariance[i];
  f.covariance_type = msg.position_covariance_type;
  return f;
}

std::optional<Eigen::Isometry3d> lookupTransform(const tf2_ros::Buffer& buffer, const std::string& target,
                                                 const std::string& source, const ros::Time& stamp,
                                                 double timeout, std::string* error) {
  if (source.empty() || target.empty()) {
    if (error) *error = "empty frame id";
    return std::nullopt;
  }
  try {
    const geometry_msgs::TransformStamped t =
        buffer.lookupTransform(target, source, stamp, ros::Duration(std::max(timeout, 0.0)));
    Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
    out.translation() << t.transform.translation.x, t.transform.translation.y, t.transform.translation.z;
    const auto& q = t.transform.rotation;
    Eigen::Quaterniond eq(q.w, q.x, q.y, q.z);
    if (!(eq.norm() > 0.0) || !out.translation().allFinite()) {
      if (error) *error = "transform is not finite";
      return std::nullopt;
    }
    out.linear() = eq.normalized().toRotationMatrix();
    return out;
  } catch (const std::exception& e) {  // tf2 exceptions, and ros::Duration's range error for absurd stamps
    if (error) *error = e.what();
    return std::nullopt;
  }
}

std::optional<core::PickerRegistry> loadPickerRegistry(const std::string& pickers_file, const char* node) {
  if (pickers_file.empty()) {
    ROS_FATAL("%s: parameter ~pickers_file (config/pickers.yaml) is required", node);
    return std::nullopt;
  }
  try {
    return core::PickerRegistry::load(pickers_file);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", node, e.what());
    return std::nullopt;
  }
}

Eigen::Isometry2d planar(const Eigen::Isometry3d& t) {
  Eigen::Isometry2d p = Eigen::Isometry2d::Identity();
  p.translation() = t.translation().head<2>();
  const double yaw = std::atan2(t.linear()(1, 0), t.linear()(0, 0));
  p.linear() = Eigen::Rotation2Dd(yaw).toRotationMatrix();
  return p;
}

void SilenceWatch::configure(double warn_after, std::string what) {
  what_ = std::move(what);
  warn_after_ = warn_after;
}

void SilenceWatch::heard() { last_ = ros::Time::now(); }

void SilenceWatch::report(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const ros::Time now = ros::Time::now();
  if (now.isZero()) return;          // sim clock not running yet
  if (start_.isZero()) start_ = now;  // the first report: quiet since here
  const ros::Time since = last_.isZero() ? start_ : last_;
  if (now < since) {  // the clock jumped back
    start_ = now;
    last_ = ros::Time();
    return;
  }
  const double quiet = (now - since).toSec();
  stat.add(what_ + ": seconds since the last", last_.isZero() ? -1.0 : quiet);
  if (warn_after_ > 0.0 && quiet > warn_after_) {
    char text[200];
    std::snprintf(text, sizeof(text), "%s: nothing for %.0f s%s", what_.c_str(), quiet,
                  last_.isZero() ? " since the start (check the topic names)" : "");
    stat.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN, text);
  }
}

}  // namespace ros_adapter
}  // namespace picker_localisation
