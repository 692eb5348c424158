// Where a simulated robot's sensors sit on its base. The defaults mirror config/robot/thorvald.urdf.in (a
// Thorvald-like 1.5 m x 1.4 m base; two 2D lasers at opposite corners facing out diagonally; two RFID
// antennas facing the lanes on either side; two cameras and three UWB anchors as in Sarmento et al. 2024, Table 1). The
// lead may fill it from the URDF (robot::RobotDescription); frame names are the URDF link names without the
// robot prefix. ROS-free.
#pragma once

#include "picker_localisation/sim/sim_types.h"

#include <string>
#include <vector>

namespace picker_localisation {
namespace sim {

struct SensorMount2D {
  std::string frame;  // link name without the "<robot_id>/" prefix
  Pose2D pose;        // in base_link, m / rad
  double z = 0.0;     // height above ground, m
};

struct RobotSensorLayout {
  double base_length = 1.5;  // m along x (footprint, also what other robots' lasers see)
  double base_width = 1.4;   // m along y
  std::vector<SensorMount2D> lasers{{"laser_front", {0.78, 0.73, 0.785398}, 0.3},
                                    {"laser_rear", {-0.78, -0.73, -2.356194}, 0.3}};
  std::vector<SensorMount2D> rfid_antennas{{"rfid_left", {0.0, 0.72, 1.570796}, 1.0},
                                           {"rfid_right", {0.0, -0.72, -1.570796}, 1.0}};
  std::vector<SensorMount2D> uwb_anchors{{"uwb_anchor_1", {-0.235, 0.0, 0.0}, 1.0},
                                         {"uwb_anchor_2", {0.235, 0.280, 0.0}, 1.0},
                                         {"uwb_anchor_3", {0.235, -0.280, 0.0}, 1.0}};
  std::vector<SensorMount2D> cameras{{"camera_1", {0.267, 0.037, 0.459}, 1.2},
                                     {"camera_2", {0.267, -0.037, -0.459}, 1.2}};
};

}  // namespace sim
}  // namespace picker_localisation
