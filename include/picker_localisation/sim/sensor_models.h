// Simulated robot sensors: 2D laser ray casting, RFID reads, UWB ranges, camera person boxes. Each model is
// a pure function of the scene and a generator passed in (the simulator owns the generators). ROS-free.
#pragma once

#include "picker_localisation/sim/sensor_layout.h"
#include "picker_localisation/sim/sim_types.h"

#include <Eigen/Core>

#include <random>
#include <vector>

namespace picker_localisation {
namespace sim {

// ---- Scene seen by the lasers --------------------------------------------------------------------------
struct Circle {
  Eigen::Vector2d centre{0.0, 0.0};
  double radius = 0.0;
};
struct Segment {
  Eigen::Vector2d a{0.0, 0.0}, b{0.0, 0.0};
};
struct LaserScene {
  std::vector<Circle> circles;    // picker legs, bed posts
  std::vector<Segment> segments;  // other robots' footprints
};

// Range along the ray origin + r * dir (dir unit) to the first hit with a circle, +inf when none (r > 0 only;
// an origin inside a circle returns +inf for that circle).
double rayCircle(const Eigen::Vector2d& origin, const Eigen::Vector2d& dir, const Circle& c);
double raySegment(const Eigen::Vector2d& origin, const Eigen::Vector2d& dir, const Segment& s);

struct LaserParams {
  double angle_min = -2.356194;         // rad (270 deg field of view, Hokuyo UTM-30LX)
  double angle_max = 2.356194;          // rad
  double angle_increment = 0.00872665;  // rad (0.5 deg; the real sensor has 0.25 deg)
  double range_min = 0.1;               // m
  double range_max = 30.0;              // m
  double range_noise_std = 0.01;        // m, Gaussian range noise per beam
  double rate = 10.0;                   // Hz
};

// Casts every beam of a laser at `sensor_pose` (map frame) against the scene (first hit of circles and
// segments), adds N(0, range_noise_std^2) to each hit (one draw per beam, hit or not). REP 117: +inf when
// nothing is hit within range_max, -inf when the noisy hit is closer than range_min. The robot's own body is
// not in the scene (the corner lasers look outwards).
LaserScanWithTruth castLaser(const LaserScene& scene, const Pose2D& sensor_pose, const LaserParams& params,
                             double stamp, std::mt19937_64& rng);

// ---- Static clutter ------------------------------------------------------------------------------------
struct ClutterParams {
  bool bed_posts = true;
  double post_spacing = 3.0;    // m between posts along a bed
  double post_offset = 0.75;    // m from a lane's centre line to the posts (half the lane spacing by default)
  double post_radius = 0.03;    // m
  double merge_distance = 0.3;  // m: posts of two adjacent lanes closer than this are merged into one
};

// ---- RFID ----------------------------------------------------------------------------------------------
// Read model (per antenna, tag and read attempt):
//   p_read(d) = p_max / (1 + exp((d - d50) / width))   for d <= max_range, 0 beyond,
//   rssi = rssi_1m - 10 n log10(max(d, 0.1)) + N(0, rssi_std^2)  [dBm],
//   phase = (4 pi d / wavelength + N(0, phase_std^2)) mod 2 pi.
// `d` is the 3D distance from the antenna to the tag (tag_height above ground).
struct RfidParams {
  double p_max = 0.95;
  double d50 = 4.0;        // m, distance where the read probability is half p_max
  double width = 0.7;      // m, steepness of the fall-off
  double max_range = 8.0;  // m
  double rssi_1m = -45.0;  // dBm at 1 m
  double path_loss_exponent = 2.0;
  double rssi_std = 2.0;       // dB
  double wavelength = 0.3456;  // m (868 MHz, EU UHF RFID)
  double phase_std = 0.1;      // rad
  double tag_height = 1.0;     // m
  double rate = 2.0;           // Hz, read attempts per antenna and tag
};
double rfidReadProbability(const RfidParams& params, double distance);
// One read attempt; false when the tag was not read (then `out` is untouched).
bool simulateRfidRead(const RfidParams& params, double distance, std::mt19937_64& rng,
                      RfidReadingWithTruth& out);

// ---- UWB -----------------------------------------------------------------------------------------------
// Two-way ranging between an anchor and a tag, 3D distance d:
//   with probability p_dropout no range; otherwise range = d + N(0, range_std^2), plus with probability
//   p_nlos a non-line-of-sight excess delay ~ Exp(mean nlos_mean) m; ranges beyond max_range are not
//   reported.
struct UwbParams {
  double range_std = 0.1;  // m
  double p_nlos = 0.05;
  double nlos_mean = 1.0;  // m
  double p_dropout = 0.02;
  double max_range = 30.0;  // m
  double tag_height = 1.0;  // m
  double rate = 10.0;       // Hz, ranges per anchor and tag
};
bool simulateUwbRange(const UwbParams& params, double distance, std::mt19937_64& rng, UwbRangeWithTruth& out);

// ---- Camera --------------------------------------------------------------------------------------------
// Pinhole camera, body frame x forward / y left / z up at height `mount.z`; the picker is an upright box of
// person_width x person_height standing on the ground, facing the camera. A box is produced when the picker's
// centre is in front, within max_range and its bearing inside the horizontal field of view, with probability
// 1 - p_miss; its edges get N(0, pixel_std^2) noise and are clipped to the image; the reported bearing is
// that of the noisy box centre (Sarmento et al. 2024, Eq. 1: atan((cx - u) / fx)). No occlusion between pickers is
// modelled.
struct CameraParams {
  int image_width = 640;    // px
  int image_height = 480;   // px
  double hfov = 1.2043;     // rad (69 deg, OAK-1-like)
  double max_range = 15.0;  // m
  double p_miss = 0.1;
  double pixel_std = 3.0;      // px
  double person_height = 1.7;  // m
  double person_width = 0.5;   // m
  double rate = 5.0;           // Hz
  double fx() const;           // px, (image_width / 2) / tan(hfov / 2); square pixels
};
// Boxes for the pickers at `positions` (map frame) seen by a camera at `camera_pose` (map frame), height z.
std::vector<CameraBox> simulateCamera(const CameraParams& params, const Pose2D& camera_pose, double camera_z,
                                      const std::vector<Eigen::Vector2d>& positions, std::mt19937_64& rng);

}  // namespace sim
}  // namespace picker_localisation
