// A simulated robot driving along the topological map's edges towards goal nodes. ROS-free.
//
// The robot moves at a constant `speed` along the shortest path (TopologicalMap::shortestPath, undirected
// motion graph) to its goal, interpolating along edges; yaw is the direction of travel (kept when stopped).
// A new goal can be set at any time: when the robot is on an edge it first drives to whichever endpoint of
// that edge gives the shorter total way (distance along the edge + pathLength(endpoint, goal)), turning back
// on the edge if that is shorter. A reached goal is kept: the robot waits on it until a new goal or
// clearGoal(). With no goal (never set, or cleared) the patrol policy chooses where to drive next:
//   kStay:    wait where it is;
//   kLanes:   visit the lane ends in order (lanes()[0] entry, far, lanes()[1] far, entry, ... the serpentine,
//             i.e. drive along every lane), cyclically; falls back to kRandom on maps without lanes;
//   kRandom:  a uniformly drawn node of its connected component (the robot's own generator).
#pragma once

#include "picker_localisation/sim/lane_layout.h"
#include "picker_localisation/sim/sim_types.h"
#include "picker_localisation/topology/topological_map.h"

#include <optional>
#include <random>
#include <string>
#include <vector>

namespace picker_localisation {
namespace sim {

enum class PatrolPolicy { kStay, kLanes, kRandom };
// "stay" | "lanes" | "random"; throws std::invalid_argument on anything else.
PatrolPolicy parsePatrolPolicy(const std::string& name);

struct RobotMotionParams {
  double speed = 1.0;  // m/s along edges
  PatrolPolicy patrol = PatrolPolicy::kLanes;
};

class SimulatedRobot {
 public:
  // Starts at `start` with yaw towards its first neighbour (0 if none), no goal.
  SimulatedRobot(const topology::TopologicalMap& map, const LaneLayout& layout, std::string id,
                 topology::NodeIndex start, const RobotMotionParams& params, std::uint64_t rng_seed);

  const std::string& id() const { return id_; }
  // Retargets the robot (takes effect immediately). Throws std::out_of_range for an invalid node.
  void setGoal(topology::NodeIndex goal);
  void clearGoal();
  std::optional<topology::NodeIndex> goal() const { return goal_; }
  // True when the robot stands on its goal node (or has none and patrol is kStay).
  bool atGoal() const;
  std::size_t goalsReached() const { return goals_reached_; }

  void step(double dt);
  const Pose2D& pose() const { return pose_; }
  double speed() const { return params_.speed; }
  // Node the robot stands on, or the endpoint it is driving to (its "current node" for planners).
  topology::NodeIndex currentNode() const;
  // Nearest node to the true pose.
  topology::NodeIndex nearestNode() const;
  bool moving() const { return moving_; }

 private:
  void plan();
  void choosePatrolGoal();

  const topology::TopologicalMap* map_;
  const LaneLayout* layout_;
  std::string id_;
  RobotMotionParams params_;
  std::mt19937_64 rng_;
  Pose2D pose_;
  topology::NodeIndex at_ = topology::kInvalidNode;  // node stood on (valid when not on an edge)
  topology::NodeIndex from_ = topology::kInvalidNode, to_ = topology::kInvalidNode;
  double edge_fraction_ = 0.0;
  bool moving_ = false;
  std::vector<topology::NodeIndex> path_;  // remaining nodes after to_
  std::optional<topology::NodeIndex> goal_;
  std::size_t patrol_index_ = 0;
  std::size_t goals_reached_ = 0;
};

}  // namespace sim
}  // namespace picker_localisation
