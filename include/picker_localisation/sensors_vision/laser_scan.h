// 2D laser scans without ROS types, and jump-distance segmentation (seed 003, Sec. 3.4.1 / 6.3.3, Algorithm 3).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace picker_localisation {
namespace sensors {

// A planar scan as sensor_msgs/LaserScan carries it (angles in rad, ranges in m). Ranges that are not finite or
// outside [range_min, range_max] are invalid returns.
struct LaserScanData {
  double stamp = 0.0;  // s, the scan's own stamp
  double angle_min = 0.0;
  double angle_increment = 0.0;
  double range_min = 0.0;
  double range_max = 0.0;
  std::vector<float> ranges;

  bool validRange(std::size_t i) const;
  double angle(std::size_t i) const { return angle_min + static_cast<double>(i) * angle_increment; }
  std::size_t validCount() const;
};

// One segment of consecutive valid beams (Algorithm 3's c_j), in the scan's own frame.
struct ScanCluster {
  std::vector<Eigen::Vector2d> points;  // m, sensor frame, in beam order
  std::vector<double> ranges;           // m, one per point
  std::size_t first_beam = 0;           // index of the first beam in the scan
  Eigen::Vector2d centroid() const;     // o_j of Algorithm 3
};

struct SegmentationOptions {
  double jump_distance = 0.13;     // d_c: consecutive points farther apart than this start a new cluster, m
  std::size_t min_points = 3;      // m_c: clusters with fewer points are dropped (Algorithm 3 "richness")
  std::size_t max_points = 200;    // clusters with more points are walls, not legs/people: dropped
  bool break_on_invalid = true;    // an invalid beam (no return) ends the current cluster
};

// Algorithm 3: walk the beams in order, start a new cluster when ||p_i - p_{i-1}|| >= d_c (or an invalid beam
// intervenes), keep clusters with min_points <= size <= max_points. Choice (not in the thesis): a scan that
// covers a full circle is not wrapped around; the first and last beams belong to different clusters.
std::vector<ScanCluster> segmentScan(const LaserScanData& scan, const SegmentationOptions& options = {});

}  // namespace sensors
}  // namespace picker_localisation
