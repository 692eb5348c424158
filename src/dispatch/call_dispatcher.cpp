#include "picker_localisation/dispatch/call_dispatcher.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace dispatch {

using topology::NodeIndex;

const char* toString(CallState s) {
  switch (s) {
    case CallState::kQueued:
      return "queued";
    case CallState::kAssigned:
      return "assigned";
    case CallState::kOnTheWay:
      return "on_the_way";
    case CallState::kArrived:
      return "arrived";
    case CallState::kToStorage:
      return "to_storage";
    case CallState::kDone:
      return "done";
    case CallState::kCancelled:
      return "cancelled";
  }
  return "?";
}

std::string DispatcherOptions::validate() const {
  if (!(robot_speed > 0.0) || !std::isfinite(robot_speed))
    return core::badValue("robot_speed", robot_speed, "> 0");
  if (!(arrival_distance > 0.0) || !std::isfinite(arrival_distance))
    return core::badValue("arrival_distance", arrival_distance, "> 0");
  if (!(load_time >= 0.0) || !std::isfinite(load_time)) return core::badValue("load_time", load_time, ">= 0");
  if (!std::isfinite(arrival_min_rssi)) return core::badValue("arrival_min_rssi", arrival_min_rssi, "finite");
  if (!(arrival_min_probability >= 0.0 && arrival_min_probability <= 1.0))
    return core::badValue("arrival_min_probability", arrival_min_probability, "in [0, 1]");
  if (!(commit_share >= 0.0 && commit_share <= 1.0))
    return core::badValue("commit_share", commit_share, "in [0, 1]");
  if (!(commit_wait >= 0.0) || !std::isfinite(commit_wait))
    return core::badValue("commit_wait", commit_wait, ">= 0");
  return "";
}

const std::vector<std::string>& DispatcherOptions::yamlKeys() {
  static const std::vector<std::string> keys = {
      "robot_speed", "arrival_distance", "load_time",        "arrival_min_rssi",       "commit_share",
      "commit_wait", "storage_node",     "arrival_by_lidar", "arrival_min_probability"};
  return keys;
}

DispatcherOptions DispatcherOptions::fromYaml(const YAML::Node& node, std::vector<std::string>* unknown) {
  DispatcherOptions o;
  const std::string c = "dispatcher";
  core::readOption(node, c, "robot_speed", o.robot_speed);
  core::readOption(node, c, "arrival_distance", o.arrival_distance);
  core::readOption(node, c, "load_time", o.load_time);
  core::readOption(node, c, "arrival_min_rssi", o.arrival_min_rssi);
  core::readOption(node, c, "commit_share", o.commit_share);
  core::readOption(node, c, "arrival_by_lidar", o.arrival_by_lidar);
  core::readOption(node, c, "arrival_min_probability", o.arrival_min_probability);
  core::readOption(node, c, "commit_wait", o.commit_wait);
  core::readOption(node, c, "storage_node", o.storage_node);
  return core::checkOptions(o, node, yamlKeys(), c, unknown);
}

std::string callLogHeader() {
  return "call_id,picker_id,robot_id,state,called,assigned,arrived,loaded,done,call_to_arrival_s,target_node";
}

std::string callLogLine(const Call& c, const topology::TopologicalMap& map) {
  std::ostringstream out;
  out.precision(12);
  const auto time = [&out](double t) {
    out << ',';
    if (std::isfinite(t)) out << t;
  };
  out << c.id << ',' << c.picker_id << ',' << c.robot_id << ',' << toString(c.state);
  time(c.stamp);
  time(c.assigned_at);
  time(c.arrived_at);
  time(c.loaded_at);
  time(c.done_at);
  time(c.arrived_at - c.stamp);
  out << ',' << (c.target < map.numNodes() ? map.node(c.target).name : std::string());
  return out.str();
}

std::string defaultStorageNode(const topology::TopologicalMap& map) {
  const topology::BoundingBox box = map.boundingBox();
  std::string best_name;
  double best = std::numeric_limits<double>::infinity();
  for (NodeIndex n = 0; n < map.numNodes(); ++n) {
    const double d = (map.position2d(n) - Eigen::Vector2d(box.min_x, box.min_y)).norm();
    if (map.lane(n) == topology::kNoLane && d < best) best = d, best_name = map.node(n).name;
  }
  return best_name;
}

CallDispatcher::CallDispatcher(std::shared_ptr<const topology::TopologicalMap> map, DispatcherOptions options,
                               std::vector<std::string> robot_ids)
    : map_(std::move(map)), options_(std::move(options)), robot_ids_(std::move(robot_ids)) {
  if (!map_ || map_->numNodes() == 0) throw std::invalid_argument("CallDispatcher: empty map");
  const std::string problem = options_.validate();
  if (!problem.empty()) throw std::invalid_argument("CallDispatcher: " + problem);
  if (robot_ids_.empty()) throw std::invalid_argument("CallDispatcher: no robot");
  if (!options_.storage_node.empty()) {
    const auto s = map_->index(options_.storage_node);
    if (!s)
      throw std::invalid_argument("CallDispatcher: storage_node '" + options_.storage_node +
                                  "' is not in the map");
    storage_ = *s;
  }
}

std::optional<std::uint64_t> CallDispatcher::call(const std::string& picker_id, double stamp,
                                                  std::string* error) {
  auto refuse = [error](const std::string& why) -> std::optional<std::uint64_t> {
    if (error) *error = why;
    return std::nullopt;
  };
  if (picker_id.empty()) return refuse("a call names its picker");
  if (!std::isfinite(stamp)) return refuse("the call's stamp is not finite");
  for (const Call& c : calls_)
    if (c.picker_id == picker_id && c.open())
      return refuse("picker " + picker_id + " has an open call (" + std::to_string(c.id) + ", " +
                    toString(c.state) + ")");
  Call c;
  c.id = next_id_++;
  c.picker_id = picker_id;
  c.stamp = stamp;
  calls_.push_back(c);
  return c.id;
}

Call* CallDispatcher::findOpen(std::uint64_t call_id) {
  for (Call& c : calls_)
    if (c.id == call_id && c.open()) return &c;
  return nullptr;
}

const Call* CallDispatcher::find(std::uint64_t call_id) const {
  for (const Call& c : calls_)
    if (c.id == call_id) return &c;
  return nullptr;
}

bool CallDispatcher::cancel(std::uint64_t call_id, double stamp, std::string* error) {
  Call* c = findOpen(call_id);
  if (!c) {
    if (error) *error = "no open call " + std::to_string(call_id);
    return false;
  }
  c->state = CallState::kCancelled;
  c->done_at = stamp;
  return true;
}

bool CallDispatcher::setBelief(const std::string& picker_id, const std::vector<NodeIndex>& nodes,
                               const std::vector<double>& masses) {
  if (nodes.empty() || nodes.size() != masses.size()) return false;
  Belief b;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (nodes[k] >= map_->numNodes() || !(masses[k] > 0.0) || !std::isfinite(masses[k])) continue;
    b.nodes.push_back(nodes[k]);
    b.masses.push_back(masses[k]);
  }
  if (b.nodes.empty() || !core::normaliseMasses(b.masses)) return false;
  beliefs_[picker_id] = std::move(b);
  return true;
}

bool CallDispatcher::setRobotNode(const std::string& robot_id, NodeIndex node) {
  if (node >= map_->numNodes() ||
      std::find(robot_ids_.begin(), robot_ids_.end(), robot_id) == robot_ids_.end())
    return false;
  robot_node_[robot_id] = node;
  return true;
}

const Call* CallDispatcher::servedBy(const std::string& robot_id) const {
  for (const Call& c : calls_)
    if (c.open() && c.robot_id == robot_id) return &c;
  return nullptr;
}

bool CallDispatcher::sighting(const std::string& robot_id, const std::string& picker_id, double stamp,
                              double distance) {
  for (Call& c : calls_) {
    if (!c.open() || c.picker_id != picker_id || c.robot_id != robot_id) continue;
    if ((c.state != CallState::kAssigned && c.state != CallState::kOnTheWay) ||
        !(distance <= options_.arrival_distance))
      return false;
    c.state = CallState::kArrived;
    // A sighting stamped just before the call (the robot was already at the picker; messages cross) is
    // arrival at the call.
    c.arrived_at = std::max(stamp, c.stamp);
    return true;
  }
  return false;
}

bool CallDispatcher::lidarPerson(const std::string& robot_id, const std::string& picker_id, double stamp,
                                 double distance, double probability) {
  return options_.arrival_by_lidar && probability >= options_.arrival_min_probability &&
         sighting(robot_id, picker_id, stamp, distance);
}

bool CallDispatcher::rfidRead(const std::string& robot_id, const std::string& picker_id, double stamp,
                              double rssi) {
  return rssi >= options_.arrival_min_rssi && sighting(robot_id, picker_id, stamp, 0.0);
}

const std::vector<double>& CallDispatcher::distancesFrom(NodeIndex source) const {
  auto it = distances_.find(source);
  if (it != distances_.end()) return it->second;
  return distances_.emplace(source, map_->pathLengthsFrom(source)).first->second;
}

double CallDispatcher::expectedDistance(NodeIndex from, const std::string& picker_id) const {
  const auto b = beliefs_.find(picker_id);
  if (b == beliefs_.end() || from >= map_->numNodes()) return std::numeric_limits<double>::infinity();
  const std::vector<double>& d = distancesFrom(from);
  double e = 0.0;
  for (std::size_t k = 0; k < b->second.nodes.size(); ++k) e += b->second.masses[k] * d[b->second.nodes[k]];
  return e;
}

NodeIndex CallDispatcher::target(const std::string& picker_id) const {
  const auto b = beliefs_.find(picker_id);
  if (b == beliefs_.end()) return topology::kInvalidNode;
  NodeIndex best = topology::kInvalidNode;
  double best_cost = std::numeric_limits<double>::infinity();
  for (NodeIndex t :
       b->second.nodes) {  // the 1-median over the support (ties: the first, the heaviest listed)
    const double cost = expectedDistance(t, picker_id);
    if (cost < best_cost - 1e-9) best_cost = cost, best = t;
  }
  return best;
}

bool CallDispatcher::laneEnd(NodeIndex n) const {
  const topology::LaneIndex l = map_->lane(n);
  if (l == topology::kNoLane) return false;
  for (NodeIndex m : map_->neighbours(n))
    if (map_->lane(m) != l) return true;
  return false;
}

NodeIndex CallDispatcher::goalFor(Call& c, double now) const {
  const NodeIndex t = target(c.picker_id);
  const topology::LaneIndex lane = t == topology::kInvalidNode ? topology::kNoLane : map_->lane(t);
  if (lane == topology::kNoLane || options_.commit_share <= 0.0) return t;
  const Belief& b = beliefs_.at(c.picker_id);
  std::map<topology::LaneIndex, double> lane_mass = map_->massPerLane(b.nodes, b.masses);
  const auto robot = robot_node_.find(c.robot_id);
  const bool in_target_lane =
      robot != robot_node_.end() && map_->lane(robot->second) == lane && !laneEnd(robot->second);
  if (lane_mass[lane] >= options_.commit_share || in_target_lane ||
      (!std::isnan(c.holding_since) && now - c.holding_since >= options_.commit_wait)) {
    if (!std::isnan(c.holding_since) && std::isnan(c.hold_ended)) c.hold_ended = now;
    return t;
  }
  // Not committed: the end of a lane carrying mass with the least expected path to the picker.
  NodeIndex best = t;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const auto& [l, mass] : lane_mass) {
    if (l == topology::kNoLane) continue;
    for (NodeIndex n : map_->laneNodes(l)) {
      if (!laneEnd(n)) continue;
      const double cost = expectedDistance(n, c.picker_id);
      if (cost < best_cost) best_cost = cost, best = n;
    }
  }
  if (robot != robot_node_.end() && robot->second == best && std::isnan(c.holding_since))
    c.holding_since = now;
  return best;
}

std::vector<Goal> CallDispatcher::update(double now) {
  std::vector<Goal> goals;
  for (Call& c : calls_) {
    if (!c.open()) continue;
    if (c.state == CallState::kAssigned) c.state = CallState::kOnTheWay;  // its goal went out last update
    if (c.state == CallState::kQueued) {
      // The free robot with the least expected travel time over the picker's belief.
      std::string best;
      double best_distance = std::numeric_limits<double>::infinity();
      for (const std::string& r : robot_ids_) {
        const auto at = robot_node_.find(r);
        if (at == robot_node_.end() || servedBy(r)) continue;
        const double e = expectedDistance(at->second, c.picker_id);
        if (e < best_distance) best_distance = e, best = r;
      }
      if (best.empty()) continue;  // no free robot, or no belief of the picker yet: stays queued
      c.robot_id = best;
      c.state = CallState::kAssigned;
      c.assigned_at = now;
      c.target = topology::kInvalidNode;
    }
    if (c.state == CallState::kAssigned || c.state == CallState::kOnTheWay) {
      const NodeIndex t = goalFor(c, now);
      if (t != topology::kInvalidNode && t != c.target) {
        c.target = t;
        goals.push_back({c.robot_id, t, c.id, c.state});
      }
    } else if (c.state == CallState::kArrived && now - c.arrived_at >= options_.load_time) {
      c.loaded_at = now;
      if (storage_ == topology::kInvalidNode) {
        c.state = CallState::kDone;
        c.done_at = now;
        continue;
      }
      c.state = CallState::kToStorage;
      c.target = storage_;
      goals.push_back({c.robot_id, storage_, c.id, c.state});
    } else if (c.state == CallState::kToStorage) {
      const auto at = robot_node_.find(c.robot_id);
      if (at != robot_node_.end() && at->second == storage_) {
        c.state = CallState::kDone;
        c.done_at = now;
      }
    }
  }
  return goals;
}

void CallDispatcher::adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                              const topology::MapChange& change) {
  if (!map || map->numNodes() == 0) throw std::invalid_argument("CallDispatcher: empty map");
  if (change.old_to_new.size() != map_->numNodes())
    throw std::invalid_argument("CallDispatcher: the map change does not fit the current map");
  NodeIndex storage = topology::kInvalidNode;
  if (!options_.storage_node.empty()) {
    const auto s = map->index(options_.storage_node);
    if (!s)
      throw std::invalid_argument("CallDispatcher: storage_node '" + options_.storage_node +
                                  "' is not in the new map");
    storage = *s;
  }
  const auto moveNode = [&](NodeIndex n) {
    return n == topology::kInvalidNode || n >= change.old_to_new.size() ? topology::kInvalidNode
                                                                        : change.old_to_new[n];
  };
  for (Call& c : calls_) c.target = moveNode(c.target);
  for (auto& [robot, node] : robot_node_) node = moveNode(node);
  for (auto& [picker, belief] : beliefs_) {
    // Two old nodes may land on one new node: their masses add up.
    std::map<NodeIndex, double> moved;
    for (std::size_t k = 0; k < belief.nodes.size(); ++k) {
      const NodeIndex n = moveNode(belief.nodes[k]);
      if (n != topology::kInvalidNode) moved[n] += belief.masses[k];
    }
    belief.nodes.clear();
    belief.masses.clear();
    for (const auto& [n, m] : moved) belief.nodes.push_back(n), belief.masses.push_back(m);
  }
  map_ = std::move(map);
  storage_ = storage;
  distances_.clear();
}

}  // namespace dispatch
}  // namespace picker_localisation
