#include "picker_localisation/sim/sensor_models.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace picker_localisation {
namespace sim {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

double rayCircle(const Eigen::Vector2d& origin, const Eigen::Vector2d& dir, const Circle& c) {
  // |o + r d - c|^2 = R^2, |d| = 1:  r^2 + 2 r (d.(o - c)) + |o - c|^2 - R^2 = 0.
  const Eigen::Vector2d oc = origin - c.centre;
  const double b = dir.dot(oc);
  const double cc = oc.squaredNorm() - c.radius * c.radius;
  if (cc <= 0.0) return kInf;  // origin inside the circle
  const double disc = b * b - cc;
  if (disc < 0.0) return kInf;
  const double r = -b - std::sqrt(disc);
  return r > 0.0 ? r : kInf;
}

double raySegment(const Eigen::Vector2d& origin, const Eigen::Vector2d& dir, const Segment& s) {
  const Eigen::Vector2d e = s.b - s.a;
  const double denom = dir.x() * e.y() - dir.y() * e.x();
  if (std::abs(denom) < 1e-12) return kInf;
  const Eigen::Vector2d w = s.a - origin;
  const double r = (w.x() * e.y() - w.y() * e.x()) / denom;
  const double u = (w.x() * dir.y() - w.y() * dir.x()) / denom;
  if (r <= 0.0 || u < 0.0 || u > 1.0) return kInf;
  return r;
}

LaserScanWithTruth castLaser(const LaserScene& scene, const Pose2D& sensor_pose, const LaserParams& params,
                             double stamp, std::mt19937_64& rng) {
  LaserScanWithTruth scan;
  scan.stamp = stamp;
  scan.angle_min = params.angle_min;
  scan.angle_increment = params.angle_increment;
  scan.range_min = params.range_min;
  scan.range_max = params.range_max;
  scan.scan_time = params.rate > 0.0 ? 1.0 / params.rate : 0.0;
  scan.sensor_pose = sensor_pose;
  const int n = std::max(
      1, static_cast<int>(std::floor((params.angle_max - params.angle_min) / params.angle_increment + 1e-9)) +
             1);
  scan.angle_max = params.angle_min + (n - 1) * params.angle_increment;
  scan.ranges.assign(static_cast<std::size_t>(n), std::numeric_limits<float>::infinity());
  const Eigen::Vector2d o = sensor_pose.position();
  std::vector<double> best(static_cast<std::size_t>(n), kInf);
  std::vector<Eigen::Vector2d> dirs(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double ang = sensor_pose.yaw + params.angle_min + i * params.angle_increment;
    dirs[static_cast<std::size_t>(i)] = Eigen::Vector2d(std::cos(ang), std::sin(ang));
  }
  // Tests the beams whose angle (relative to the sensor) lies in [lo, hi] (rad, any branch of the angle).
  auto castWindow = [&](double lo, double hi, auto&& hit) {
    for (double shift : {-2.0 * M_PI, 0.0, 2.0 * M_PI}) {
      const int i0 =
          std::max(0, static_cast<int>(std::ceil((lo + shift - params.angle_min) / params.angle_increment)));
      const int i1 = std::min(
          n - 1, static_cast<int>(std::floor((hi + shift - params.angle_min) / params.angle_increment)));
      for (int i = i0; i <= i1; ++i) {
        const double r = hit(dirs[static_cast<std::size_t>(i)]);
        if (r < best[static_cast<std::size_t>(i)]) best[static_cast<std::size_t>(i)] = r;
      }
    }
  };
  auto relAngle = [&](const Eigen::Vector2d& v) {
    return std::remainder(std::atan2(v.y(), v.x()) - sensor_pose.yaw, 2.0 * M_PI);
  };
  const double reach = params.range_max + 1.0;
  // Circles: only the beams inside each circle's angular extent.
  for (const auto& c : scene.circles) {
    const Eigen::Vector2d v = c.centre - o;
    const double d = v.norm();
    if (d - c.radius > reach || d <= c.radius) continue;
    const double half = std::asin(std::min(1.0, c.radius / d));
    const double rel = relAngle(v);
    castWindow(rel - half, rel + half, [&](const Eigen::Vector2d& dir) { return rayCircle(o, dir, c); });
  }
  // Segments: the beams between the angles of the two endpoints (a segment off the origin subtends < pi).
  for (const auto& sg : scene.segments) {
    if (std::min((sg.a - o).norm(), (sg.b - o).norm()) > reach + (sg.b - sg.a).norm()) continue;
    const double a1 = relAngle(sg.a - o);
    const double span = std::remainder(relAngle(sg.b - o) - a1, 2.0 * M_PI);
    const double margin = 1e-9;
    castWindow(std::min(a1, a1 + span) - margin, std::max(a1, a1 + span) + margin,
               [&](const Eigen::Vector2d& dir) { return raySegment(o, dir, sg); });
  }
  std::normal_distribution<double> noise(0.0, params.range_noise_std);
  for (int i = 0; i < n; ++i) {
    double r = best[static_cast<std::size_t>(i)];
    // Noise is drawn for every beam so the stream does not depend on what is hit.
    const double eps = params.range_noise_std > 0.0 ? noise(rng) : 0.0;
    if (!std::isfinite(r)) continue;
    r += eps;
    if (r > params.range_max) continue;  // +inf: no return in range
    if (r < params.range_min) {
      scan.ranges[static_cast<std::size_t>(i)] = -std::numeric_limits<float>::infinity();  // too close
      continue;
    }
    scan.ranges[static_cast<std::size_t>(i)] = static_cast<float>(r);
  }
  return scan;
}

double rfidReadProbability(const RfidParams& p, double distance) {
  if (!(distance >= 0.0) || distance > p.max_range) return 0.0;
  return p.p_max / (1.0 + std::exp((distance - p.d50) / p.width));
}

bool simulateRfidRead(const RfidParams& p, double distance, std::mt19937_64& rng, RfidReadingWithTruth& out) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  // Fixed number of draws per attempt (determinism does not depend on read outcomes).
  const double draw = u(rng), rssi_noise = n(rng), phase_noise = n(rng);
  if (draw >= rfidReadProbability(p, distance)) return false;
  out.rssi =
      p.rssi_1m - 10.0 * p.path_loss_exponent * std::log10(std::max(distance, 0.1)) + p.rssi_std * rssi_noise;
  out.has_phase = true;
  const double phase = 4.0 * M_PI * distance / p.wavelength + p.phase_std * phase_noise;
  out.phase = std::fmod(std::fmod(phase, 2.0 * M_PI) + 2.0 * M_PI, 2.0 * M_PI);
  out.true_distance = distance;
  return true;
}

bool simulateUwbRange(const UwbParams& p, double distance, std::mt19937_64& rng, UwbRangeWithTruth& out) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  std::exponential_distribution<double> e(1.0);
  const double drop = u(rng), nlos = u(rng), white = n(rng), excess = e(rng);
  if (drop < p.p_dropout || distance > p.max_range) return false;
  out.true_range = distance;
  out.nlos = nlos < p.p_nlos;
  out.range = std::max(0.0, distance + p.range_std * white + (out.nlos ? p.nlos_mean * excess : 0.0));
  out.variance = p.range_std * p.range_std;
  return true;
}

double CameraParams::fx() const {
  return 0.5 * image_width / std::tan(0.5 * hfov);
}

std::vector<CameraBox> simulateCamera(const CameraParams& p, const Pose2D& camera_pose, double camera_z,
                                      const std::vector<Eigen::Vector2d>& positions, std::mt19937_64& rng) {
  std::vector<CameraBox> boxes;
  const double fx = p.fx(), cx = 0.5 * p.image_width, cy = 0.5 * p.image_height;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, p.pixel_std);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const double miss = u(rng), conf = u(rng);
    const double n1 = n(rng), n2 = n(rng), n3 = n(rng), n4 = n(rng);
    const Eigen::Vector2d q = camera_pose.inverseTransform(positions[i]);  // x forward, y left
    const double depth = q.x();
    const double dist = q.norm();
    if (depth <= 0.3 || dist > p.max_range) continue;
    const double bearing = std::atan2(q.y(), q.x());
    if (std::abs(bearing) > 0.5 * p.hfov) continue;
    if (miss < p.p_miss) continue;
    // Projection (image u to the right, v down): u = cx - fx * y / x, v = cy - fy * (z - camera_z) / x.
    const double half_w = 0.5 * p.person_width;
    double u_left = cx - fx * (q.y() + half_w) / depth + n1;
    double u_right = cx - fx * (q.y() - half_w) / depth + n2;
    double v_top = cy - fx * (p.person_height - camera_z) / depth + n3;
    double v_bottom = cy - fx * (0.0 - camera_z) / depth + n4;
    u_left = std::clamp(u_left, 0.0, double(p.image_width - 1));
    u_right = std::clamp(u_right, 0.0, double(p.image_width - 1));
    v_top = std::clamp(v_top, 0.0, double(p.image_height - 1));
    v_bottom = std::clamp(v_bottom, 0.0, double(p.image_height - 1));
    if (u_right - u_left < 2.0 || v_bottom - v_top < 2.0) continue;
    CameraBox b;
    b.x_offset = static_cast<int>(std::lround(u_left));
    b.y_offset = static_cast<int>(std::lround(v_top));
    b.width = static_cast<int>(std::lround(u_right - u_left));
    b.height = static_cast<int>(std::lround(v_bottom - v_top));
    const double centre_u = b.x_offset + 0.5 * b.width;
    b.bearing = std::atan((cx - centre_u) / fx);
    // Confidence falls with distance: 0.95 near, 0.5 at max_range, jittered by +-0.05.
    b.confidence = std::clamp(0.95 - 0.45 * dist / p.max_range + 0.1 * (conf - 0.5), 0.0, 1.0);
    b.picker_index = i;
    b.true_bearing = bearing;
    b.true_distance = dist;
    boxes.push_back(b);
  }
  return boxes;
}

}  // namespace sim
}  // namespace picker_localisation
