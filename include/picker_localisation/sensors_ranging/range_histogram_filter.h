// Range Histogram Filter (seed 004 Sec. 4.3, Eqs. 2-7): a robot-centred 2D grid fusing UWB ranges from
// anchors on the robot (annuli) with camera bearings (wedges), innovation by dilation with a maximum speed,
// and the P_min floors. ROS-free; one filter per tracked tag.
//
// Grids are float, row-major, cell (ix, iy) centred at (min + (i + 0.5) * resolution) in the robot frame
// (REP 103 base_link: x forward, y left), the robot at the grid centre.
// Choices where the paper is vague (written here once):
//  * "Intersection" (Eqs. 2, 4) is the cell-wise product followed by Eq. 3 normalisation.
//  * Eq. 3: f(p) = p / P_max when p / P_max > p_threshold, else P_min (so every grid lies in [P_min, 1]).
//  * UWB range grid (Eq. 5, "exponential distribution along the radial axis", Fig. 4): per anchor
//    p = exp(-|r - |c - a|| / b), b = sigma / sqrt(2) (Laplace with the range variance sigma^2); anchors are
//    combined by product, then Eq. 3 with P_min^uwb. Only the annulus |r - |c-a|| < b ln(1/p_threshold) is
//    evaluated (outside it Eq. 3 gives P_min anyway), which is what makes an update cheap.
//  * Camera grid (Eq. 6): per bearing a Gaussian in the angle difference (sigma_bearing); several detections
//    combine by max (any detected person may be the target); Eq. 3 with P_min^cam. No bearing: grid = 1.
//  * Innovation (Eq. 7): M^I = dilate(M_{t-1}, U dt) with a square (Chebyshev) structuring element of half
//    width ceil(U dt / resolution) cells (van Herk / Gil-Werman, O(1) per cell), floored at P_min^inov. It is
//    computed at update time with the actual dt (the paper computes it one cycle ahead at a fixed rate). When
//    the robot moved between updates the previous grid is first re-sampled into the new robot frame (nearest
//    cell; cells that enter the grid get P_min^inov).
//  * Output: the weighted mean and covariance of the cells with M > output_threshold (weights M), plus the
//    cell's own variance res^2/12 on each axis.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>
#include <vector>

namespace picker_localisation {
namespace sensors {

struct RhfOptions {
  double size_x = 20.0;            // m, grid extent along robot x (centred on the robot)
  double size_y = 20.0;            // m
  double resolution = 0.05;        // m per cell
  double max_speed = 1.5;          // U, m/s: fastest plausible person speed (innovation dilation)
  double p_threshold = 0.01;       // Eq. 3 threshold on p / P_max
  double p_min_uwb = 0.05;         // Eq. 5 floor (P_min^uwb < P_min^cam: UWB identifies the target)
  double p_min_cam = 0.3;          // Eq. 6 floor
  double p_min_obs = 0.05;         // Eq. 4 floor
  double p_min_inov = 0.01;        // Eq. 7 floor (P_min^inov < P_min^obs: trust the motion bound more)
  double default_range_sigma = 0.15;   // m, when a range has no variance
  double default_bearing_sigma = 0.05; // rad, when a bearing has no sigma
  double output_threshold = 0.5;   // cells of M above this (in [0,1]) make the position estimate
};

// A range from an anchor on the robot (robot frame).
struct RangeMeasurement {
  Eigen::Vector2d anchor = Eigen::Vector2d::Zero();  // m, anchor position in the robot frame
  double range = 0.0;                                // m
  double variance = 0.0;                             // m^2 (<= 0: default_range_sigma^2)
};

// A bearing to a person from a sensor on the robot (camera, or a PDoA angle), robot frame.
struct BearingMeasurement {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // m, sensor position in the robot frame
  double bearing = 0.0;                              // rad, direction in the robot frame (x fwd, y left)
  double sigma = 0.0;                                // rad (<= 0: default_bearing_sigma)
};

struct RhfEstimate {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();           // m, robot frame
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();     // m^2, robot frame
  std::size_t support_cells = 0;                                // cells above output_threshold
};

class RangeHistogramFilter {
 public:
  // Throws std::invalid_argument on non-positive sizes / resolution or floors outside (0, 1].
  explicit RangeHistogramFilter(RhfOptions options = {});

  // One filter cycle at `stamp` (s). `robot_motion`: pose of the current robot frame in the robot frame of
  // the previous update (identity for a still robot). Ranges with a non-finite or negative range / anchor are
  // ignored (callers should reject them first). Needs at least one valid range; returns nullopt (and leaves
  // the filter unchanged) when there is none or when stamp < the previous stamp.
  std::optional<RhfEstimate> update(double stamp, const std::vector<RangeMeasurement>& ranges,
                                    const std::vector<BearingMeasurement>& bearings = {},
                                    const Eigen::Isometry2d& robot_motion = Eigen::Isometry2d::Identity());

  void reset();  // back to the uniform prior
  bool initialised() const { return initialised_; }
  double lastStamp() const { return last_stamp_; }

  // Grid access (tests, visualisation).
  int cellsX() const { return nx_; }
  int cellsY() const { return ny_; }
  Eigen::Vector2d cellCentre(int ix, int iy) const;
  const std::vector<float>& grid() const { return m_; }  // M_t after the last update (size nx * ny)
  const RhfOptions& options() const { return options_; }

 private:
  void rangeGrid(const std::vector<RangeMeasurement>& ranges, std::vector<float>& out);
  bool bearingGrid(const std::vector<BearingMeasurement>& bearings, std::vector<float>& out);
  void innovation(double dt, const Eigen::Isometry2d& robot_motion);
  void dilate(std::vector<float>& g, int half_width);
  RhfEstimate estimate() const;

  RhfOptions options_;
  int nx_ = 0, ny_ = 0;
  double min_x_ = 0.0, min_y_ = 0.0;
  bool initialised_ = false;
  double last_stamp_ = 0.0;
  std::vector<float> m_, inov_, obs_, tmp_, scratch_;
};

// Eq. 3 applied in place: p -> p / max when p / max > threshold, else p_min. A grid whose max is not > 0
// becomes all p_min.
void normaliseGrid(std::vector<float>& grid, float threshold, float p_min);

}  // namespace sensors
}  // namespace picker_localisation
