#include "picker_localisation/sim/sim_types.h"

#include <cmath>
#include <iterator>

namespace picker_localisation {
namespace sim {

Eigen::Vector2d Pose2D::transform(const Eigen::Vector2d& local) const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {x + c * local.x() - s * local.y(), y + s * local.x() + c * local.y()};
}

Eigen::Vector2d Pose2D::inverseTransform(const Eigen::Vector2d& world) const {
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double dx = world.x() - x, dy = world.y() - y;
  return {c * dx + s * dy, -s * dx + c * dy};
}

Pose2D Pose2D::compose(const Pose2D& child) const {
  const Eigen::Vector2d p = transform(child.position());
  return {p.x(), p.y(), std::remainder(yaw + child.yaw, 2.0 * M_PI)};
}

namespace {
template <typename T>
void moveAppend(std::vector<T>& to, std::vector<T>& from) {
  to.insert(to.end(), std::make_move_iterator(from.begin()), std::make_move_iterator(from.end()));
}
}  // namespace

void SimOutputs::clear() {
  calls.clear();
  gnss.clear();
  scans.clear();
  rfid.clear();
  uwb.clear();
  camera.clear();
}

void SimOutputs::append(SimOutputs&& other) {
  moveAppend(calls, other.calls);
  moveAppend(gnss, other.gnss);
  moveAppend(scans, other.scans);
  moveAppend(rfid, other.rfid);
  moveAppend(uwb, other.uwb);
  moveAppend(camera, other.camera);
}

}  // namespace sim
}  // namespace picker_localisation
