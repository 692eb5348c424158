// Geometric features of one 2D laser cluster for leg classification (after Arras et al. 2007 and Leigh et al.
// 2015: size, spread, width, linearity, circularity, boundary, curvature, distance). ROS-free.
#pragma once

#include <array>
#include <string>

#include "picker_localisation/sensors_vision/laser_scan.h"

namespace picker_localisation {
namespace vision {

struct LegFeatures {
  // Shape only: the number of points and the distance from the sensor are left out on purpose (they depend on
  // the scanner's angular resolution and on where people happened to stand in the recordings; with them the
  // forest generalised worse to the held-out recording and would not transfer to other lasers).
  static constexpr int kCount = 11;
  // Order of values():
  //  0 std. deviation from the centroid, m      1 mean absolute deviation from the median point, m
  //  2 width (first-to-last point), m            3 linearity (residual of the total least-squares line), m^2
  //  4 circularity (residual of the circle fit), m^2   5 radius of the fitted circle, m
  //  6 boundary length (sum of consecutive distances), m  7 boundary regularity (std. dev. of those), m
  //  8 curvature (Menger, first/middle/last point), 1/m  9 mean inscribed angle, rad
  // 10 occluded flag: a neighbouring beam is nearer than the cluster edge (0/1)
  std::array<float, kCount> values{};

  static LegFeatures compute(const ScanCluster& cluster, const core::LaserScan* scan = nullptr);
  static std::string name(int i);
};

}  // namespace vision
}  // namespace picker_localisation
