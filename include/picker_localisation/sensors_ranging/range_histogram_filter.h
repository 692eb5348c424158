// Range Histogram Filter (Sarmento et al. 2024, Sec. 4.3, Eqs. 2-7): a robot-centred 2D grid fusing UWB ranges from
// anchors on the robot (annuli) with camera bearings (wedges), innovation by dilation with a maximum speed,
// and the P_min floors. ROS-free; one filter per tracked tag.
//
// Frames: measurements are given in the robot frame (REP 103 base_link: x forward, y left) together with the
// robot pose in a fixed frame (map or odom). The grid is axis-aligned in that fixed frame and re-centred on
// the robot at every update by an integer number of cells (exact, no interpolation, no drift; the robot stays
// within half a cell of the grid centre, which is the paper's robot-centred grid without rotating it).
// Grids are float, row-major (index iy * nx + ix), cell (ix, iy) centred at min + (i + 0.5) * resolution.
// Choices where the paper is vague (written here once):
//  * "Intersection" (Eqs. 2, 4) is the cell-wise product followed by Eq. 3 normalisation.
//  * Eq. 3: f(p) = max(p / P_max, P_min) when p / P_max > p_threshold, else P_min (every grid lies in
//    [P_min, 1]; the max keeps f monotonic when p_threshold < P_min).
//  * UWB range grid (Eq. 5, "exponential distribution along the radial axis", Fig. 4): per anchor
//    p = exp(-|r - |c - a|| / b), b = sigma / sqrt(2) (Laplace with the range variance sigma^2), P_max = 1
//    (the density's peak); anchors are combined by product, then Eq. 3 with P_min^uwb. Only the annulus
//    |r - |c-a|| < b ln(1/p_threshold) is evaluated (outside it Eq. 3 gives P_min anyway): this is what makes
//    an update cheap.
//  * Camera grid (Eq. 6): per bearing p = exp(-0.5 (angle difference / sigma)^2) in front of the sensor, P_max
//    = 1; the detections that pass the camera gate (see RhfOptions::camera_gate) combine by max (any detected
//    person may be the target); Eq. 3 with P_min^cam. No bearing passes: the camera grid is 1 everywhere.
//  * Innovation (Eq. 7): M^I = dilate(M_{t-1}, U dt) with a square (Chebyshev) structuring element of half
//    width ceil(U dt / resolution) cells (van Herk / Gil-Werman, O(1) per cell), then Eq. 3 with P_min^inov.
//    It is computed at update time with the actual dt (the paper computes it one cycle ahead at a fixed
//    rate). Cells that enter the grid when it is re-centred start at 0 (-> P_min^inov).
//  * M_t (Eq. 2) = (M^O * M^I) / max.
//  * Output: the weighted mean and covariance of the cells with M > output_threshold (weights M), plus the
//    cell's own variance res^2/12 on each axis, in the fixed frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <utility>
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
  // Camera association gate: a bearing is used only when its wedge reaches UWB cells of normalised value
  // >= camera_gate (max over the wedge of M^uwb * wedge); 0 uses every bearing. Cameras see every person and
  // may miss the target (occlusion, field of view): without the gate a bystander's wedge would pull the
  // estimate along the UWB arc. Not in Sarmento et al. 2024 (which follows one person).
  double camera_gate = 0.1;
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
  Eigen::Vector2d position = Eigen::Vector2d::Zero();           // m, fixed frame
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();     // m^2, fixed frame
  std::size_t support_cells = 0;                                // cells above output_threshold
  std::size_t bearings_used = 0;                                // bearings that passed the camera gate
  bool touches_border = false;  // a support cell lies on the grid's edge: the person may be outside the grid
};

class RangeHistogramFilter {
 public:
  // Throws std::invalid_argument on non-positive sizes / resolution or floors outside (0, 1].
  explicit RangeHistogramFilter(RhfOptions options = {});

  // One filter cycle at `stamp` (s). `robot_pose`: base_link in the fixed frame at `stamp` (identity when
  // the caller works in the robot frame and the robot does not move). Ranges with a non-finite or negative range / anchor are
  // ignored (callers should reject them first). Needs at least one valid range; returns nullopt (and leaves
  // the filter unchanged) when there is none or when stamp < the previous stamp.
  std::optional<RhfEstimate> update(double stamp, const std::vector<RangeMeasurement>& ranges,
                                    const std::vector<BearingMeasurement>& bearings = {},
                                    const Eigen::Isometry2d& robot_pose = Eigen::Isometry2d::Identity());

  void reset();  // back to the uniform prior
  bool initialised() const { return initialised_; }
  double lastStamp() const { return last_stamp_; }

  // Grid access (tests, visualisation).
  int cellsX() const { return nx_; }
  int cellsY() const { return ny_; }
  Eigen::Vector2d cellCentre(int ix, int iy) const;  // fixed frame, m
  const std::vector<float>& grid() const { return m_; }  // M_t after the last update (size nx * ny)
  const RhfOptions& options() const { return options_; }

 private:
  // Implementation note: M^uwb and M^cam are constant (their floors) except on the annuli / wedges, so they are
  // kept as sparse corrections (factor grids reset through the list of touched cells); the dense work per
  // update is the dilation (rows, then columns fused with the product of Eq. 2) and one pass for the
  // normalisation + estimate.
  float rangeGrid(const std::vector<RangeMeasurement>& ranges, const Eigen::Isometry2d& pose);
  std::size_t bearingGrid(const std::vector<BearingMeasurement>& bearings, const Eigen::Isometry2d& pose,
                          float inv_fmax);
  void touch(std::size_t i);
  void dilateRows(int shift_x, int shift_y, int k);
  void dilateColumnsTimes(int k, float scale, bool dilate_source);
  RhfEstimate normaliseAndEstimate();

  RhfOptions options_;
  int nx_ = 0, ny_ = 0;
  double min_x_ = 0.0, min_y_ = 0.0;
  bool initialised_ = false;
  double last_stamp_ = 0.0;
  std::vector<float> m_;       // M_t (max 1 after an update)
  std::vector<float> tmp_;     // row-dilated M_{t-1}
  std::vector<float> uwb_;     // UWB factor relative to its floor product (1 = untouched)
  std::vector<float> cam_;     // camera value (P_min^cam = untouched)
  std::vector<std::uint8_t> mark_;
  std::vector<std::uint32_t> touched_;
  std::vector<float> buf_g_, buf_h_;
  std::vector<std::pair<std::uint32_t, float>> wedge_;  // cells of one bearing's wedge and their values
};

// Eq. 3 applied in place: p -> max(p / max, p_min) when p / max > threshold, else p_min. A grid whose max is not > 0
// becomes all p_min.
void normaliseGrid(std::vector<float>& grid, float threshold, float p_min);

}  // namespace sensors
}  // namespace picker_localisation
