// Plain data types produced by the farm simulator: poses, GNSS fixes, laser scans, RFID reads, UWB ranges and
// camera detections, each the core raw measurement plus its ground truth (the farm_sim node only copies them
// into messages), so the simulator core and the offline experiment runner need no ROS. ROS-free.
#pragma once

#include <Eigen/Core>

#include "picker_localisation/core/sensor_data.h"

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace picker_localisation {
namespace sim {

// A planar pose in the map frame (REP 103: metres, yaw in rad counter-clockwise from the map x axis).
struct Pose2D {
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
  Eigen::Vector2d position() const { return {x, y}; }
  // Transforms a point given in this pose's frame into the parent frame.
  Eigen::Vector2d transform(const Eigen::Vector2d& local) const;
  // Transforms a point given in the parent frame into this pose's frame.
  Eigen::Vector2d inverseTransform(const Eigen::Vector2d& world) const;
  // This pose composed with a child pose given in this pose's frame.
  Pose2D compose(const Pose2D& child) const;
};

// The raw measurements are core's (core/sensor_data.h), as the nodes' message conversions produce them; the
// simulator adds the ground truth behind each one for tests and the evaluator (it never reaches an
// estimator). frame_id carries the robot prefix as the published header does ("robot_1/laser_front"); `mount`
// is the sensor's name in the sensor layout ("laser_front").

// A fix of a picker's unit (status -1 NO_FIX during a blackout: lat/lon/alt are NaN then).
struct GnssFixWithTruth : core::GnssFix {
  std::string picker_id;
  std::size_t picker_index = 0;
  // The error-free position and the error actually added (offset + drift + white noise), map frame, m.
  Eigen::Vector2d true_position{0.0, 0.0};
  Eigen::Vector2d error{0.0, 0.0};
  bool in_blackout = false;
};

// A scan of one of a robot's lasers (ranges +inf where a beam hits nothing within range_max, REP 117).
struct LaserScanWithTruth : core::LaserScan {
  std::string robot_id;
  std::size_t robot_index = 0;
  std::string mount;   // "laser_front" / "laser_rear"
  Pose2D sensor_pose;  // laser pose in the map frame at the stamp (ground truth)
};

// A read of a picker's tag by one of a robot's antennas.
struct RfidReadingWithTruth : core::RfidReading {
  std::size_t robot_index = 0;
  std::string mount;             // "rfid_left" / "rfid_right"
  std::size_t picker_index = 0;  // ground truth
  double true_distance = 0.0;    // m, antenna to tag (ground truth)
};

// A range from one of a robot's UWB anchors to a picker's tag.
struct UwbRangeWithTruth : core::UwbRange {
  std::size_t robot_index = 0;
  std::string mount;             // "uwb_anchor_1" ...
  std::size_t picker_index = 0;  // ground truth
  double true_range = 0.0;       // m
  bool nlos = false;             // ground truth: this range carries a non-line-of-sight excess delay
};

// picker_localisation/BearingDetection (one person box).
struct CameraBox {
  int x_offset = 0;              // px, left edge
  int y_offset = 0;              // px, top edge
  int width = 0;                 // px
  int height = 0;                // px
  double bearing = 0.0;          // rad in the camera body frame (x forward, y left), positive to the left
  double confidence = 0.0;       // [0, 1]
  std::size_t picker_index = 0;  // ground truth
  double true_bearing = 0.0;     // rad
  double true_distance = 0.0;    // m
};

// picker_localisation/BearingDetectionArray of one camera image.
struct CameraFrame {
  double stamp = 0.0;
  std::string robot_id;
  std::size_t robot_index = 0;
  std::string frame;  // camera body frame without the robot prefix: "camera_1" / "camera_2"
  int image_width = 0;
  int image_height = 0;
  std::vector<CameraBox> boxes;
};

// Everything the simulator produced during one step (or one advanceTo), in time order per sensor.
// A picker whose trays are full calls a robot (the call scenario, SimConfig::calls) and waits where it
// stands.
struct PickerCall {
  double stamp = 0.0;
  std::size_t picker_index = 0;
  std::string picker_id;
  std::string reported_row;  // the lane the picker says it is in ("" none); sometimes a wrong one
};

struct SimOutputs {
  std::vector<PickerCall> calls;
  std::vector<GnssFixWithTruth> gnss;
  std::vector<LaserScanWithTruth> scans;
  std::vector<RfidReadingWithTruth> rfid;
  std::vector<UwbRangeWithTruth> uwb;
  std::vector<CameraFrame> camera;
  void clear();
  void append(SimOutputs&& other);
};

}  // namespace sim
}  // namespace picker_localisation
