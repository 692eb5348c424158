// Jump-distance segmentation of 2D laser scans (core::LaserScan) (Antonucci 2022, Sec. 3.4.1 / 6.3.3, Algorithm 3).
#pragma once

#include <Eigen/Core>

#include "picker_localisation/core/sensor_data.h"

#include <vector>

namespace picker_localisation {
namespace vision {

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
std::vector<ScanCluster> segmentScan(const core::LaserScan& scan, const SegmentationOptions& options = {});

// Every `step`-th beam of a scan (angle_increment x step): the same recording as a coarser laser would see
// it, for measuring how the leg detector transfers across angular resolutions. step 0 or 1 returns the scan.
core::LaserScan decimateScan(const core::LaserScan& scan, std::size_t step);

}  // namespace vision
}  // namespace picker_localisation
