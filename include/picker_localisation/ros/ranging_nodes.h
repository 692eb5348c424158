// What the ROS adapters of the sensors_ranging front-ends share (gnss_ingest_node.h, rfid_ranging_node.h,
// uwb_ranging_node.h: thin, parameters -> core objects, messages -> core types -> picker_localisation/Observation on
// /observations). Parameters and topics: docs/readme/sensors_ranging.md and config/gnss_ingest.yaml,
// config/rfid_ranging.yaml, config/uwb_ranging.yaml.
#pragma once

#include "picker_localisation/ros/node_diagnostics.h"
#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <picker_localisation/BearingDetectionArray.h>
#include <picker_localisation/GnssBias.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBeliefArray.h>
#include <picker_localisation/PickerList.h>
#include <picker_localisation/RfidReading.h>
#include <picker_localisation/UwbRange.h>
#include <ros/ros.h>
#include <sensor_msgs/NavSatFix.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/core/stamp_ordered_buffer.h"
#include "picker_localisation/ros/fleet_topics.h"
#include "picker_localisation/ros/last_value_publisher.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/stamp_guard.h"
#include "picker_localisation/sensors_ranging/gnss_fleet.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "picker_localisation/sensors_ranging/picker_association.h"
#include "picker_localisation/sensors_ranging/rfid_observation_model.h"
#include "picker_localisation/sensors_ranging/uwb_ranging.h"

namespace picker_localisation {
namespace ros_adapter {

// sensor_msgs/NavSatFix -> core GnssFix (no checks: GnssIngest does them).
core::GnssFix gnssFixFromMsg(const sensor_msgs::NavSatFix& msg);
// A good fix (STATUS_FIX, diagonal covariance sigma^2 horizontally, (2 sigma)^2 vertically, altitude 50 m) at a
// map position, as a phone would send it (tests, bench_fleet).
sensor_msgs::NavSatFix navSatFixAt(const core::GeodeticDatum& datum, const Eigen::Vector2d& map_xy,
                                   const ros::Time& stamp, double sigma = 1.0);

// Looks up `target <- source` at `stamp`, waiting at most `timeout` s. nullopt (and *error set) when the
// transform is not available (unknown frame, extrapolation, empty frame id).
std::optional<Eigen::Isometry3d> lookupTransform(const tf2_ros::Buffer& buffer, const std::string& target,
                                                 const std::string& source, const ros::Time& stamp,
                                                 double timeout, std::string* error);
// The picker registry from the required pickers_file; nullopt after one ROS_FATAL line naming `node`.
std::optional<core::PickerRegistry> loadPickerRegistry(const std::string& pickers_file, const char* node);
// A front-end's input that should be talking (a mistyped topic must not look green): once
// warn_after s of ROS time (a node's silent_warn_after, default 30; 0 = never) pass without a message, since
// the start or since the last one, the node's diagnostics go WARN naming the input and how long it has been
// quiet.
class SilenceWatch {
 public:
  void configure(double warn_after, std::string what);
  void heard();  // a message arrived
  // Adds "<what>: seconds since the last" and, when silent too long, merges a WARN into the summary.
  void report(diagnostic_updater::DiagnosticStatusWrapper& stat);

 private:
  std::string what_;
  double warn_after_ = 30.0;
  ros::Time start_, last_;
};

// Planar part of a 3D transform: x, y and the yaw of the x axis.
Eigen::Isometry2d planar(const Eigen::Isometry3d& t);

}  // namespace ros_adapter
}  // namespace picker_localisation
