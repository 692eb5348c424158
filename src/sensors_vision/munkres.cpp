#include "picker_localisation/sensors_vision/munkres.h"

#include <limits>
#include <stdexcept>

namespace picker_localisation {
namespace vision {

// Hungarian algorithm, shortest augmenting path with row/column potentials (the O(n^3) form of Munkres'
// method). The matrix is transposed when it has more rows than columns so that rows <= columns.
std::vector<int> solveAssignment(const Eigen::MatrixXd& cost_in) {
  const int rows_in = static_cast<int>(cost_in.rows());
  const int cols_in = static_cast<int>(cost_in.cols());
  std::vector<int> result(rows_in, -1);
  if (rows_in == 0 || cols_in == 0) return result;
  if (!cost_in.allFinite()) throw std::invalid_argument("solveAssignment: costs must be finite");
  const bool transposed = rows_in > cols_in;
  const Eigen::MatrixXd cost = transposed ? Eigen::MatrixXd(cost_in.transpose()) : cost_in;
  const int n = static_cast<int>(cost.rows());  // n <= m
  const int m = static_cast<int>(cost.cols());
  const double inf = std::numeric_limits<double>::infinity();
  // 1-based arrays; p[j] = row matched to column j (0: none); u, v potentials.
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<char> used(m + 1, 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j]) continue;
        const double cur = cost(i0 - 1, j - 1) - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  for (int j = 1; j <= m; ++j) {
    if (p[j] == 0) continue;
    if (transposed)
      result[j - 1] = p[j] - 1;
    else
      result[p[j] - 1] = j - 1;
  }
  return result;
}

double assignmentCost(const Eigen::MatrixXd& cost, const std::vector<int>& row_to_col) {
  double total = 0.0;
  for (std::size_t r = 0; r < row_to_col.size(); ++r)
    if (row_to_col[r] >= 0) total += cost(static_cast<int>(r), row_to_col[r]);
  return total;
}

}  // namespace vision
}  // namespace picker_localisation
