#include "picker_localisation/sensors_vision/leg_features.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace picker_localisation {
namespace vision {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(mid), v.end());
  return v[mid];
}

// Algebraic (Kasa) circle fit: x^2 + y^2 + a x + b y + c = 0 by least squares.
bool fitCircle(const std::vector<Eigen::Vector2d>& pts, Eigen::Vector2d& centre, double& radius) {
  if (pts.size() < 3) return false;
  Eigen::MatrixXd A(pts.size(), 3);
  Eigen::VectorXd rhs(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    A(static_cast<long>(i), 0) = pts[i].x();
    A(static_cast<long>(i), 1) = pts[i].y();
    A(static_cast<long>(i), 2) = 1.0;
    rhs(static_cast<long>(i)) = -pts[i].squaredNorm();
  }
  const Eigen::Vector3d s = A.colPivHouseholderQr().solve(rhs);
  centre = Eigen::Vector2d(-s(0) / 2.0, -s(1) / 2.0);
  const double r2 = centre.squaredNorm() - s(2);
  if (!(r2 > 0.0) || !std::isfinite(r2)) return false;
  radius = std::sqrt(r2);
  return true;
}

}  // namespace

LegFeatures LegFeatures::compute(const ScanCluster& cluster, const core::LaserScan* scan) {
  LegFeatures f;
  const auto& pts = cluster.points;
  const std::size_t n = pts.size();
  if (n == 0) return f;
  const Eigen::Vector2d c = cluster.centroid();

  double var = 0.0;
  std::vector<double> xs, ys;
  for (const auto& p : pts) {
    var += (p - c).squaredNorm();
    xs.push_back(p.x());
    ys.push_back(p.y());
  }
  f.values[0] = static_cast<float>(std::sqrt(var / static_cast<double>(n)));

  const Eigen::Vector2d med(median(xs), median(ys));
  double mad = 0.0;
  for (const auto& p : pts) mad += (p - med).norm();
  f.values[1] = static_cast<float>(mad / static_cast<double>(n));

  f.values[2] = static_cast<float>((pts.back() - pts.front()).norm());

  // Linearity: mean squared distance to the total least-squares line = smallest covariance eigenvalue.
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const auto& p : pts) cov += (p - c) * (p - c).transpose();
  cov /= static_cast<double>(n);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  f.values[3] = static_cast<float>(std::max(0.0, eig.eigenvalues()(0)));

  Eigen::Vector2d centre;
  double radius = 0.0;
  if (fitCircle(pts, centre, radius)) {
    double res = 0.0;
    for (const auto& p : pts) res += std::pow(radius - (p - centre).norm(), 2);
    f.values[4] = static_cast<float>(res / static_cast<double>(n));
    f.values[5] = static_cast<float>(std::min(radius, 10.0));  // a straight segment fits a huge circle
  } else {
    f.values[4] = 0.0f;
    f.values[5] = 10.0f;
  }

  std::vector<double> steps;
  double length = 0.0;
  for (std::size_t i = 1; i < n; ++i) {
    steps.push_back((pts[i] - pts[i - 1]).norm());
    length += steps.back();
  }
  f.values[6] = static_cast<float>(length);
  if (!steps.empty()) {
    const double mean = length / static_cast<double>(steps.size());
    double sv = 0.0;
    for (double s : steps) sv += (s - mean) * (s - mean);
    f.values[7] = static_cast<float>(std::sqrt(sv / static_cast<double>(steps.size())));
  }

  // Curvature: Menger curvature of the first, middle and last point (consecutive triples are dominated by range
  // noise when the points are dense, i.e. close to the sensor); mean inscribed angle: angle at each interior
  // point between the rays to the first and the last point.
  double angle = 0.0;
  int interior = 0;
  if (n >= 3) {
    const Eigen::Vector2d a = pts.front(), b = pts[n / 2], d = pts.back();
    const double ab = (b - a).norm(), bd = (d - b).norm(), ad = (d - a).norm();
    const double cross = std::abs((b - a).x() * (d - a).y() - (b - a).y() * (d - a).x());
    f.values[8] = ab * bd * ad > 1e-12 ? static_cast<float>(2.0 * cross / (ab * bd * ad)) : 0.0f;
  }
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const Eigen::Vector2d u = pts.front() - pts[i], v = pts.back() - pts[i];
    if (u.norm() > 1e-9 && v.norm() > 1e-9) {
      angle += std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0));
      ++interior;
    }
  }
  f.values[9] = interior ? static_cast<float>(angle / interior) : 0.0f;

  if (scan != nullptr && !cluster.ranges.empty()) {
    const std::size_t first = cluster.first_beam, last = cluster.first_beam + n - 1;
    bool occluded = false;
    // A nearer valid return right next to either edge hides part of the cluster.
    if (first > 0 && scan->validRange(first - 1) && scan->ranges[first - 1] < cluster.ranges.front())
      occluded = true;
    if (last + 1 < scan->ranges.size() && scan->validRange(last + 1) && scan->ranges[last + 1] < cluster.ranges.back())
      occluded = true;
    f.values[10] = occluded ? 1.0f : 0.0f;
  }
  return f;
}

std::string LegFeatures::name(int i) {
  static const char* names[kCount] = {"std_dev",         "median_abs_dev",      "width",     "linearity",
                                      "circularity",     "radius",              "boundary_length",
                                      "boundary_regularity", "curvature",       "inscribed_angle", "occluded"};
  return (i >= 0 && i < kCount) ? names[i] : "";
}

}  // namespace vision
}  // namespace picker_localisation
