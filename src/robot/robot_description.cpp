#include "picker_localisation/robot/robot_description.h"

#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>

namespace picker_localisation {
namespace robot {

double SensorMount::yaw() const {
  const Eigen::Matrix3d r = pose.rotation();
  return std::atan2(r(1, 0), r(0, 0));
}

namespace {
Eigen::Isometry3d toEigen(const urdf::Pose& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  t.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).normalized().toRotationMatrix();
  return t;
}
}  // namespace

RobotDescription RobotDescription::fromUrdf(const std::string& xml, const std::string& prefix,
                                            const std::string& base_link) {
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model) throw std::runtime_error("robot description: the URDF could not be parsed");
  urdf::LinkConstSharedPtr base = model->getLink(prefix + base_link);
  if (!base) throw std::runtime_error("robot description: no link '" + prefix + base_link + "'");
  RobotDescription d;
  d.name_ = model->getName();
  std::function<void(const urdf::LinkConstSharedPtr&, const Eigen::Isometry3d&)> walk =
      [&](const urdf::LinkConstSharedPtr& link, const Eigen::Isometry3d& pose) {
        SensorMount m;
        m.link = link->name.compare(0, prefix.size(), prefix) == 0 ? link->name.substr(prefix.size()) : link->name;
        m.pose = pose;
        d.mounts_.push_back(m);
        for (const urdf::JointSharedPtr& j : link->child_joints) {
          urdf::LinkConstSharedPtr child = model->getLink(j->child_link_name);
          if (child) walk(child, pose * toEigen(j->parent_to_joint_origin_transform));
        }
      };
  walk(base, Eigen::Isometry3d::Identity());
  std::sort(d.mounts_.begin(), d.mounts_.end(), [](const SensorMount& a, const SensorMount& b) { return a.link < b.link; });
  return d;
}

RobotDescription RobotDescription::fromTemplateFile(const std::string& path, const std::string& robot_id) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the robot description");
  std::stringstream s;
  s << in.rdbuf();
  std::string xml = s.str();
  const std::string prefix = robot_id.empty() ? "" : robot_id + "/";
  for (std::size_t pos = xml.find("@PREFIX@"); pos != std::string::npos; pos = xml.find("@PREFIX@", pos + prefix.size()))
    xml.replace(pos, 8, prefix);
  return fromUrdf(xml, prefix);
}

std::optional<SensorMount> RobotDescription::mount(const std::string& link) const {
  for (const SensorMount& m : mounts_)
    if (m.link == link) return m;
  return std::nullopt;
}

std::vector<SensorMount> RobotDescription::mountsStartingWith(const std::string& stem) const {
  std::vector<SensorMount> out;
  for (const SensorMount& m : mounts_)
    if (m.link.compare(0, stem.size(), stem) == 0) out.push_back(m);
  return out;
}

}  // namespace robot
}  // namespace picker_localisation
