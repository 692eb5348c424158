// Geometric features of one 2D laser cluster for leg classification (after Arras et al. 2007 and Leigh et al.
// 2015: size, spread, width, linearity, circularity, boundary, curvature, distance). ROS-free.
#pragma once

#include <array>
#include <string>

#include "picker_localisation/sensors_vision/laser_scan.h"

namespace picker_localisation {
namespace sensors {

struct LegFeatures {
  static constexpr int kCount = 13;
  // Order of values():
  //  0 number of points               1 std. deviation from the centroid, m
  //  2 mean absolute deviation from the median point, m    3 width (first-to-last point), m
  //  4 linearity (residual of the total least-squares line), m^2   5 circularity (residual of the circle fit), m^2
  //  6 radius of the fitted circle, m 7 boundary length (sum of consecutive distances), m
  //  8 boundary regularity (std. dev. of consecutive distances), m  9 mean curvature (Menger), 1/m
  // 10 mean inscribed angle, rad      11 distance of the centroid from the sensor, m
  // 12 occluded flag: a neighbouring beam is nearer than the cluster edge (0/1)
  std::array<float, kCount> values{};

  static LegFeatures compute(const ScanCluster& cluster, const LaserScanData* scan = nullptr);
  static std::string name(int i);
};

}  // namespace sensors
}  // namespace picker_localisation
