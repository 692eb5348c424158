#include "picker_localisation/sensors_vision/cloud3d_person_detector.h"

#include <pcl/ModelCoefficients.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <algorithm>
#include <cmath>

namespace picker_localisation {
namespace vision {

Cloud3dPersonDetector::Cloud3dPersonDetector(Cloud3dPersonOptions options) : options_(options) {}

std::vector<Cloud3dPerson> Cloud3dPersonDetector::detect(const pcl::PointCloud<pcl::PointXYZ>& cloud) const {
  std::vector<Cloud3dPerson> out;
  auto finite = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : cloud.points)
    // z is gated too: a finite but huge z (1e38 from a corrupted cloud) overflowed the voxel grid's sums into
    // Inf, and PCL's k-d tree aborts the process on an Inf point (found by test_fuzz_inputs).
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) &&
        std::hypot(p.x, p.y) <= options_.max_range && std::abs(p.z) <= options_.max_range)
      finite->push_back(p);
  if (finite->empty()) return out;

  auto voxels = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(finite);
  const float leaf = static_cast<float>(options_.voxel_size);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.filter(*voxels);

  // Ground: the dominant plane whose normal is within ground_max_tilt of z (RANSAC). SACSegmentation built
  // with random = false seeds its generator with a constant: same cloud, same plane.
  auto objects = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  if (voxels->size() >= 3) {
    pcl::SACSegmentation<pcl::PointXYZ> seg(false);
    seg.setOptimizeCoefficients(true);
    seg.setModelType(pcl::SACMODEL_PERPENDICULAR_PLANE);
    seg.setMethodType(pcl::SAC_RANSAC);
    seg.setAxis(Eigen::Vector3f::UnitZ());
    seg.setEpsAngle(options_.ground_max_tilt);
    seg.setDistanceThreshold(options_.ground_distance);
    seg.setMaxIterations(options_.ground_iterations);
    seg.setInputCloud(voxels);
    pcl::PointIndices::Ptr inliers(new pcl::PointIndices);
    pcl::ModelCoefficients coefficients;
    seg.segment(*inliers, coefficients);
    pcl::ExtractIndices<pcl::PointXYZ> extract;
    extract.setInputCloud(voxels);
    extract.setIndices(inliers);
    extract.setNegative(true);
    extract.filter(*objects);
  } else {
    *objects = *voxels;
  }
  if (objects->empty()) return out;

  auto tree = pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
  tree->setInputCloud(objects);
  std::vector<pcl::PointIndices> clusters;
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(options_.cluster_tolerance);
  ec.setMinClusterSize(options_.min_cluster_points);
  ec.setMaxClusterSize(options_.max_cluster_points);
  ec.setSearchMethod(tree);
  ec.setInputCloud(objects);
  ec.extract(clusters);

  for (const auto& idx : clusters) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = Eigen::Vector3d::Constant(-1e9);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i : idx.indices) {
      const auto& p = (*objects)[static_cast<std::size_t>(i)];
      const Eigen::Vector3d q(p.x, p.y, p.z);
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
      sum += q;
    }
    const Eigen::Vector3d extent = hi - lo;
    const double width = std::max(extent.x(), extent.y());
    if (extent.z() < options_.min_height || extent.z() > options_.max_height) continue;
    if (width < options_.min_width || width > options_.max_width) continue;
    Cloud3dPerson person;
    person.centroid = sum / static_cast<double>(idx.indices.size());
    person.extent = extent;
    person.points = idx.indices.size();
    // Confidence: 1 at a typical 1.7 m x 0.5 m person, falling linearly to 0.5 at the gate limits.
    const double h = std::abs(extent.z() - 1.7) / std::max(1e-6, options_.max_height - options_.min_height);
    const double w = std::abs(width - 0.5) / std::max(1e-6, options_.max_width - options_.min_width);
    person.confidence = std::clamp(1.0 - 0.5 * std::max(h, w), 0.5, 1.0);
    out.push_back(person);
  }
  return out;
}

}  // namespace vision
}  // namespace picker_localisation
