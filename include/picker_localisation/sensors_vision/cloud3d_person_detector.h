// People candidates in a 3D LiDAR cloud: PCL voxel grid, ground-plane removal (RANSAC plane near horizontal),
// Euclidean cluster extraction, size gate on each cluster's bounding box. ROS-free (PCL types only).
#pragma once

#include <Eigen/Core>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <vector>

namespace picker_localisation {
namespace vision {

struct Cloud3dPersonOptions {
  double voxel_size = 0.05;          // m
  double ground_distance = 0.08;     // RANSAC inlier distance to the ground plane, m
  double ground_max_tilt = 0.25;     // max angle between the ground normal and z, rad
  int ground_iterations = 100;
  double cluster_tolerance = 0.15;   // m
  int min_cluster_points = 15;
  int max_cluster_points = 20000;
  double min_height = 0.9, max_height = 2.2;   // bounding-box extent in z, m
  double min_width = 0.15, max_width = 1.2;    // larger horizontal extent, m
  double max_range = 15.0;           // points farther (horizontally) are ignored, m
};

struct Cloud3dPerson {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // m, cloud frame
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();    // bounding box size, m
  std::size_t points = 0;
  double confidence = 0.0;                            // how well the size fits a standing person, [0, 1]
};

class Cloud3dPersonDetector {
 public:
  explicit Cloud3dPersonDetector(Cloud3dPersonOptions options = {});
  // The cloud's z axis must point up (transform to base_link first).
  std::vector<Cloud3dPerson> detect(const pcl::PointCloud<pcl::PointXYZ>& cloud) const;

 private:
  Cloud3dPersonOptions options_;
};

}  // namespace vision
}  // namespace picker_localisation
