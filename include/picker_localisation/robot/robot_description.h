// Sensor mounts of a robot read from its URDF with urdfdom, for components that need them without tf
// (the simulator placing its sensors, offline tools). ROS-free.
#pragma once

#include <Eigen/Geometry>

#include <optional>
#include <string>
#include <vector>

namespace picker_localisation {
namespace robot {

struct SensorMount {
  std::string link;                                      // link name without the robot prefix
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // in the base link's frame
  double x() const { return pose.translation().x(); }
  double y() const { return pose.translation().y(); }
  double z() const { return pose.translation().z(); }
  double yaw() const;                                    // rotation about z, rad
};

class RobotDescription {
 public:
  // Parses URDF XML. `prefix` ("robot_1/" or "") is stripped from link names; `base_link` (unprefixed) is the
  // root every pose is expressed in. Throws std::runtime_error with one line on invalid XML, a missing base link
  // or a link not connected to it.
  static RobotDescription fromUrdf(const std::string& xml, const std::string& prefix = "",
                                   const std::string& base_link = "base_link");
  // Reads a URDF template (config/robot/thorvald.urdf.in) and substitutes @PREFIX@ with "<robot_id>/".
  static RobotDescription fromTemplateFile(const std::string& path, const std::string& robot_id);

  const std::string& name() const { return name_; }
  std::optional<SensorMount> mount(const std::string& link) const;
  // Every mount whose link name starts with `stem` (e.g. "uwb_anchor_"), sorted by link name.
  std::vector<SensorMount> mountsStartingWith(const std::string& stem) const;
  const std::vector<SensorMount>& mounts() const { return mounts_; }

 private:
  std::string name_;
  std::vector<SensorMount> mounts_;
};

}  // namespace robot
}  // namespace picker_localisation
