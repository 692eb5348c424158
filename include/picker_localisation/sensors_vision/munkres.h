// Munkres (Hungarian) assignment for rectangular cost matrices (OpenCV has none). Used by the cluster tracker
// (Antonucci 2022, Sec. 6.3.3, Algorithm 4 line 2). ROS-free.
#pragma once

#include <Eigen/Core>

#include <vector>

namespace picker_localisation {
namespace vision {

// Minimum-cost assignment of rows to columns of an n x m matrix of finite costs. Returns, for each row, the
// assigned column or -1 (when n > m some rows stay unassigned). min(n, m) pairs are always assigned.
// O(max(n,m)^3) (shortest augmenting path form with potentials).
std::vector<int> solveAssignment(const Eigen::MatrixXd& cost);

// Total cost of an assignment returned by solveAssignment().
double assignmentCost(const Eigen::MatrixXd& cost, const std::vector<int>& row_to_col);

}  // namespace vision
}  // namespace picker_localisation
