#include "picker_localisation/sim/robot_motion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace picker_localisation {
namespace sim {

using topology::NodeIndex;

PatrolPolicy parsePatrolPolicy(const std::string& name) {
  if (name == "stay") return PatrolPolicy::kStay;
  if (name == "lanes") return PatrolPolicy::kLanes;
  if (name == "random") return PatrolPolicy::kRandom;
  throw std::invalid_argument("unknown patrol policy '" + name + "' (stay | lanes | random)");
}

SimulatedRobot::SimulatedRobot(const topology::TopologicalMap& map, const LaneLayout& layout, std::string id,
                               NodeIndex start, const RobotMotionParams& params, std::uint64_t rng_seed)
    : map_(&map), layout_(&layout), id_(std::move(id)), params_(params), rng_(rng_seed), at_(start) {
  if (start >= map.numNodes()) throw std::out_of_range("SimulatedRobot: start node out of range");
  if (!(params_.speed > 0.0)) throw std::invalid_argument("SimulatedRobot: speed must be > 0");
  const Eigen::Vector2d p = map.position2d(start);
  pose_ = {p.x(), p.y(), 0.0};
  if (!map.neighbours(start).empty()) {
    const Eigen::Vector2d q = map.position2d(map.neighbours(start).front());
    pose_.yaw = std::atan2(q.y() - p.y(), q.x() - p.x());
  }
  // Start the lane patrol at the lane end nearest the start node.
  if (!layout.empty()) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < 2 * layout.lanes().size(); ++i) {
      const auto& lane = layout.lanes()[i / 2];
      const bool odd = (i / 2) % 2 == 1;
      const NodeIndex n = ((i % 2 == 0) != odd) ? lane.entry_end() : lane.far_end();
      const double d = map.distance(start, n);
      if (d < best) best = d, patrol_index_ = i;
    }
  }
}

void SimulatedRobot::setGoal(NodeIndex goal) {
  if (goal >= map_->numNodes()) throw std::out_of_range("SimulatedRobot::setGoal: node out of range");
  goal_ = goal;
  plan();
}

void SimulatedRobot::clearGoal() {
  goal_.reset();
  path_.clear();
}

bool SimulatedRobot::atGoal() const {
  if (moving_) return false;
  if (!goal_) return params_.patrol == PatrolPolicy::kStay;
  return at_ == *goal_ && path_.empty();
}

NodeIndex SimulatedRobot::currentNode() const {
  return moving_ ? to_ : at_;
}

NodeIndex SimulatedRobot::nearestNode() const {
  return map_->nearestNode(pose_.position());
}

void SimulatedRobot::plan() {
  path_.clear();
  if (!goal_) return;
  const NodeIndex goal = *goal_;
  if (moving_) {
    // Drive to whichever endpoint of the current edge gives the shorter way to the goal.
    const double len = map_->distance(from_, to_);
    const double via_to = (1.0 - edge_fraction_) * len + map_->pathLength(to_, goal);
    const double via_from = edge_fraction_ * len + map_->pathLength(from_, goal);
    if (via_from < via_to) {
      std::swap(from_, to_);
      edge_fraction_ = 1.0 - edge_fraction_;
    }
    auto p = map_->shortestPath(to_, goal);
    if (p.size() > 1) path_.assign(p.begin() + 1, p.end());
  } else {
    auto p = map_->shortestPath(at_, goal);
    if (p.size() > 1) path_.assign(p.begin() + 1, p.end());
  }
}

void SimulatedRobot::choosePatrolGoal() {
  PatrolPolicy policy = params_.patrol;
  if (policy == PatrolPolicy::kLanes && layout_->empty()) policy = PatrolPolicy::kRandom;
  if (policy == PatrolPolicy::kStay) return;
  NodeIndex target = at_;
  if (policy == PatrolPolicy::kLanes) {
    // Serpentine over the lane ends: lane k is driven entry -> far when k is even, far -> entry when odd.
    const auto& lanes = layout_->lanes();
    for (std::size_t tries = 0; tries < 2 * lanes.size() && target == at_; ++tries) {
      patrol_index_ = (patrol_index_ + 1) % (2 * lanes.size());
      const auto& lane = lanes[patrol_index_ / 2];
      const bool odd = (patrol_index_ / 2) % 2 == 1;
      target = ((patrol_index_ % 2 == 0) != odd) ? lane.entry_end() : lane.far_end();
      if (map_->component(target) != map_->component(at_)) target = at_;
    }
  } else {
    std::uniform_int_distribution<std::size_t> pick(0, map_->numNodes() - 1);
    for (int tries = 0; tries < 100 && target == at_; ++tries) {
      const NodeIndex n = static_cast<NodeIndex>(pick(rng_));
      if (map_->component(n) == map_->component(at_)) target = n;
    }
  }
  if (target == at_) return;
  auto p = map_->shortestPath(at_, target);
  if (p.size() > 1) path_.assign(p.begin() + 1, p.end());
}

void SimulatedRobot::step(double dt) {
  if (!(dt >= 0.0)) throw std::invalid_argument("SimulatedRobot::step: dt must be >= 0");
  double remaining = dt * params_.speed;  // metres to drive
  int guard = 0;
  while (remaining > 1e-12 && ++guard < 100000) {
    if (!moving_) {
      // A goal, once reached, is kept (the robot waits there) until a new goal or clearGoal().
      if (path_.empty() && !goal_) choosePatrolGoal();
      if (path_.empty()) break;
      from_ = at_;
      to_ = path_.front();
      path_.erase(path_.begin());
      edge_fraction_ = 0.0;
      moving_ = true;
    }
    const double len = map_->distance(from_, to_);
    const double left = (1.0 - edge_fraction_) * len;
    if (len > 1e-9)
      pose_.yaw = std::atan2(map_->position2d(to_).y() - map_->position2d(from_).y(),
                             map_->position2d(to_).x() - map_->position2d(from_).x());
    if (left > remaining) {
      edge_fraction_ += remaining / len;
      remaining = 0.0;
    } else {
      remaining -= left;
      at_ = to_;
      moving_ = false;
      edge_fraction_ = 0.0;
      if (goal_ && at_ == *goal_ && path_.empty()) ++goals_reached_;
    }
  }
  const Eigen::Vector2d a = map_->position2d(moving_ ? from_ : at_);
  const Eigen::Vector2d b = map_->position2d(moving_ ? to_ : at_);
  const Eigen::Vector2d p = a + edge_fraction_ * (b - a);
  pose_.x = p.x();
  pose_.y = p.y();
}

}  // namespace sim
}  // namespace picker_localisation
