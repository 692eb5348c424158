// Raw measurements as their ROS messages carry them, without ROS types: one definition each, produced by the
// farm simulator and by the nodes' message conversions, consumed by the front-ends (gnss_ingest,
// leg_detector, rfid_ranging, uwb_ranging) and by the offline runner. ROS-free.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace picker_localisation {
namespace core {

// sensor_msgs/NavSatFix.
struct GnssFix {
  double stamp = 0.0;      // s, the fix's own time stamp
  double latitude = 0.0;   // deg WGS84 (NaN while the receiver has no fix)
  double longitude = 0.0;  // deg WGS84
  double altitude = 0.0;   // m above the ellipsoid (NaN allowed: not used for the horizontal position then)
  int status = 0;          // NavSatStatus: -1 NO_FIX, 0 FIX, 1 SBAS_FIX, 2 GBAS_FIX
  std::array<double, 9> position_covariance{};  // row-major ENU position covariance, m^2
  int covariance_type = 0;                      // 0 UNKNOWN, 1 APPROXIMATED, 2 DIAGONAL_KNOWN, 3 KNOWN
};

// sensor_msgs/LaserScan without intensities (angles in rad, ranges in m). Ranges that are not finite or
// outside [range_min, range_max] are invalid returns (REP 117: +inf where a beam hits nothing).
struct LaserScan {
  double stamp = 0.0;  // s, the scan's own stamp
  std::string frame_id;
  double angle_min = 0.0;
  double angle_max = 0.0;
  double angle_increment = 0.0;
  double range_min = 0.0;
  double range_max = 0.0;
  double scan_time = 0.0;  // s between scans
  std::vector<float> ranges;

  bool validRange(std::size_t i) const;
  double angle(std::size_t i) const { return angle_min + static_cast<double>(i) * angle_increment; }
  std::size_t validCount() const;
};

// picker_localisation/RfidReading: one read of a tag by an antenna.
struct RfidReading {
  double stamp = 0.0;    // s
  std::string robot_id;  // the robot that carries the antenna
  std::string frame_id;  // the antenna's frame (with the robot prefix, as in the message header)
  std::string tag_id;
  double rssi = 0.0;  // dBm
  bool has_phase = false;
  double phase = 0.0;  // rad in [0, 2 pi)
};

// picker_localisation/UwbRange: one two-way range between an anchor on a robot and a picker's tag.
struct UwbRange {
  double stamp = 0.0;    // s
  std::string robot_id;  // the robot that carries the anchor
  std::string frame_id;  // the anchor's frame (with the robot prefix, as in the message header)
  std::string tag_id;
  double range = 0.0;                // m
  double variance = 0.0;             // m^2 (<= 0: the receiver's configured default)
  std::optional<double> pdoa_angle;  // rad in the anchor frame, positive to the left (PDoA anchors only)
};

}  // namespace core
}  // namespace picker_localisation
