// The shipped URDF: sensor mounts read with urdfdom match Sarmento et al. 2024, Table 1 and the documented layout.
#include <gtest/gtest.h>

#include <cmath>

#include "picker_localisation/robot/robot_description.h"

using picker_localisation::robot::RobotDescription;

namespace {
const std::string kTemplate = std::string(PL_PACKAGE_DIR) + "/config/robot/thorvald.urdf.in";
}

TEST(RobotDescription, UwbAnchorsAndCamerasAsSeed004Table1) {
  RobotDescription d = RobotDescription::fromTemplateFile(kTemplate, "robot_1");
  auto anchors = d.mountsStartingWith("uwb_anchor_");
  ASSERT_EQ(anchors.size(), 3u);
  const double table[3][2] = {{-0.235, 0.0}, {0.235, 0.280}, {0.235, -0.280}};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(anchors[static_cast<std::size_t>(i)].x(), table[i][0], 1e-9);
    EXPECT_NEAR(anchors[static_cast<std::size_t>(i)].y(), table[i][1], 1e-9);
  }
  auto cam1 = d.mount("camera_1");
  ASSERT_TRUE(cam1);
  EXPECT_NEAR(cam1->x(), 0.267, 1e-9);
  EXPECT_NEAR(cam1->y(), 0.037, 1e-9);
  EXPECT_NEAR(cam1->yaw(), 0.459, 1e-6);
  EXPECT_NEAR(d.mount("camera_2")->yaw(), -0.459, 1e-6);
}

TEST(RobotDescription, LasersAtOppositeCorners) {
  RobotDescription d = RobotDescription::fromTemplateFile(kTemplate, "robot_2");
  auto front = d.mount("laser_front"), rear = d.mount("laser_rear");
  ASSERT_TRUE(front && rear);
  EXPECT_NEAR(front->x(), -rear->x(), 1e-9);
  EXPECT_NEAR(front->y(), -rear->y(), 1e-9);
  EXPECT_GT(front->x() * front->y(), 0.0);  // front-left and rear-right
  // Facing outwards: yaw differs by pi.
  EXPECT_NEAR(std::fabs(std::remainder(front->yaw() - rear->yaw(), 2 * M_PI)), M_PI, 1e-6);
  // The optical frame is a child of the camera: its pose composes both joints.
  auto optical = d.mount("camera_1_optical");
  ASSERT_TRUE(optical);
  EXPECT_NEAR(optical->z(), 1.2, 1e-9);
  EXPECT_EQ(d.mountsStartingWith("rfid_").size(), 2u);
}

TEST(RobotDescription, Errors) {
  EXPECT_THROW(RobotDescription::fromUrdf("<robot name='x'><link name='a'/></robot>"), std::runtime_error);
  EXPECT_THROW(RobotDescription::fromUrdf("not xml"), std::runtime_error);
  EXPECT_THROW(RobotDescription::fromTemplateFile("/nonexistent.urdf", "r"), std::runtime_error);
  // Without a prefix the template still parses (names keep no prefix).
  EXPECT_NO_THROW(RobotDescription::fromTemplateFile(kTemplate, ""));
}
