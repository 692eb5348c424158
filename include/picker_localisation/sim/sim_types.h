// Plain data types produced by the farm simulator: poses, GNSS fixes, laser scans, RFID reads, UWB ranges and
// camera detections. They mirror the ROS messages field by field (the farm_sim node only copies them), so
// the simulator core and the offline experiment runner need no ROS. ROS-free.
#pragma once

#include <Eigen/Core>

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

// sensor_msgs/NavSatFix without the header type (status: -1 NO_FIX, 0 FIX, as sensor_msgs/NavSatStatus).
struct GnssFix {
  double stamp = 0.0;  // simulated time, s
  std::string picker_id;
  std::size_t picker_index = 0;
  int status = 0;          // 0 STATUS_FIX, -1 STATUS_NO_FIX (blackout; lat/lon/alt are NaN then)
  double latitude = 0.0;   // deg (WGS84)
  double longitude = 0.0;  // deg
  double altitude = 0.0;   // m above the ellipsoid
  std::array<double, 9> position_covariance{};  // ENU, m^2, row-major
  int covariance_type = 2;                      // 0 unknown, 1 approximated, 2 diagonal known, 3 known
  // Ground truth for tests and the evaluator (never published as the fix): the error-free position and the
  // error actually added (offset + drift + white noise), map frame, m.
  Eigen::Vector2d true_position{0.0, 0.0};
  Eigen::Vector2d error{0.0, 0.0};
  bool in_blackout = false;
};

// sensor_msgs/LaserScan (no intensities). Ranges are +inf where a beam hits nothing within range_max
// (REP 117).
struct LaserScan {
  double stamp = 0.0;
  std::string robot_id;
  std::size_t robot_index = 0;
  std::string frame;             // laser frame without the robot prefix: "laser_front" / "laser_rear"
  double angle_min = 0.0;        // rad
  double angle_max = 0.0;        // rad
  double angle_increment = 0.0;  // rad
  double range_min = 0.0;        // m
  double range_max = 0.0;        // m
  double scan_time = 0.0;        // s between scans
  std::vector<float> ranges;     // m
  Pose2D sensor_pose;            // laser pose in the map frame at the stamp (ground truth)
};

// picker_localisation/RfidReading.
struct RfidRead {
  double stamp = 0.0;
  std::string robot_id;
  std::size_t robot_index = 0;
  std::string frame;  // antenna frame without the robot prefix: "rfid_left" / "rfid_right"
  std::string tag_id;
  double rssi = 0.0;  // dBm
  bool has_phase = true;
  double phase = 0.0;            // rad in [0, 2 pi)
  std::size_t picker_index = 0;  // ground truth
  double true_distance = 0.0;    // m, antenna to tag (ground truth)
};

// picker_localisation/UwbRange.
struct UwbReading {
  double stamp = 0.0;
  std::string robot_id;
  std::size_t robot_index = 0;
  std::string frame;  // anchor frame without the robot prefix: "uwb_anchor_1" ...
  std::string tag_id;
  double range = 0.0;            // m
  double variance = 0.0;         // m^2 (the configured white-noise variance)
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
struct SimOutputs {
  std::vector<GnssFix> gnss;
  std::vector<LaserScan> scans;
  std::vector<RfidRead> rfid;
  std::vector<UwbReading> uwb;
  std::vector<CameraFrame> camera;
  void clear();
  void append(SimOutputs&& other);
};

}  // namespace sim
}  // namespace picker_localisation
