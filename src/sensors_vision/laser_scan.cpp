#include "picker_localisation/sensors_vision/laser_scan.h"

#include <cmath>

namespace picker_localisation {
namespace vision {

Eigen::Vector2d ScanCluster::centroid() const {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  if (points.empty()) return c;
  for (const auto& p : points) c += p;
  return c / static_cast<double>(points.size());
}

std::vector<ScanCluster> segmentScan(const core::LaserScan& scan, const SegmentationOptions& options) {
  std::vector<ScanCluster> out;
  if (!std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_increment)) return out;
  ScanCluster current;
  auto close = [&]() {
    // Algorithm 3 line 6: keep the object only when dim(c_j) > m_c (here >= min_points, <= max_points).
    if (current.points.size() >= options.min_points && current.points.size() <= options.max_points)
      out.push_back(std::move(current));
    current = ScanCluster();
  };
  bool have_previous = false;
  Eigen::Vector2d previous;
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    if (!scan.validRange(i)) {
      if (options.break_on_invalid && !current.points.empty()) {
        close();
        have_previous = false;
      }
      continue;
    }
    const double r = scan.ranges[i];
    const double a = scan.angle(i);
    const Eigen::Vector2d p(r * std::cos(a), r * std::sin(a));
    if (have_previous && (p - previous).norm() >= options.jump_distance) close();  // line 3 / line 9
    if (current.points.empty()) current.first_beam = i;
    current.points.push_back(p);
    current.ranges.push_back(r);
    previous = p;
    have_previous = true;
  }
  if (!current.points.empty()) close();
  return out;
}

core::LaserScan decimateScan(const core::LaserScan& scan, std::size_t step) {
  if (step <= 1) return scan;
  core::LaserScan out = scan;
  out.ranges.clear();
  for (std::size_t i = 0; i < scan.ranges.size(); i += step) out.ranges.push_back(scan.ranges[i]);
  out.angle_increment = scan.angle_increment * static_cast<double>(step);
  out.angle_max = out.angle_min +
                  out.angle_increment * static_cast<double>(out.ranges.empty() ? 0 : out.ranges.size() - 1);
  return out;
}

}  // namespace vision
}  // namespace picker_localisation
