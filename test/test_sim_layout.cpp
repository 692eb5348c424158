// The simulator's built-in sensor layout mirrors the robot URDF (config/robot/thorvald.urdf.in), and
// farm_sim's ~urdf_template reader returns the same mounts.
#include <gtest/gtest.h>

#include "picker_localisation/ros/farm_sim_node.h"

using namespace picker_localisation;

namespace {
void expectSameMounts(const std::vector<sim::SensorMount2D>& a, const std::vector<sim::SensorMount2D>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].frame, b[k].frame);
    EXPECT_NEAR(a[k].pose.x, b[k].pose.x, 1e-6) << a[k].frame;
    EXPECT_NEAR(a[k].pose.y, b[k].pose.y, 1e-6) << a[k].frame;
    EXPECT_NEAR(std::remainder(a[k].pose.yaw - b[k].pose.yaw, 2 * M_PI), 0.0, 1e-6) << a[k].frame;
    EXPECT_NEAR(a[k].z, b[k].z, 1e-6) << a[k].frame;
  }
}
}  // namespace

TEST(SimLayout, DefaultsMirrorTheUrdf) {
  const sim::RobotSensorLayout urdf = ros_adapter::sensorLayoutFromUrdfTemplate(
      std::string(PL_PACKAGE_DIR) + "/config/robot/thorvald.urdf.in");
  const sim::RobotSensorLayout defaults;
  // mountsStartingWith sorts by name: laser_front < laser_rear, camera_1 < camera_2, ... as the defaults.
  expectSameMounts(urdf.lasers, defaults.lasers);
  expectSameMounts(urdf.rfid_antennas, defaults.rfid_antennas);
  expectSameMounts(urdf.uwb_anchors, defaults.uwb_anchors);
  expectSameMounts(urdf.cameras, defaults.cameras);
  EXPECT_THROW(ros_adapter::sensorLayoutFromUrdfTemplate("/nonexistent.urdf"), std::runtime_error);
}
