// Answering a picker's call (Khan et al. 2020 Sec. III-A: the Call-A-Robot app sends the picker's identity
// and time; Navigate-and-Seek Sec. VI-B: the robot "navigates towards the node estimated by the particle
// filter"). ROS-free: the dispatcher node and the offline runner drive the same class.
//
// A call goes queued -> assigned -> on the way -> arrived -> to storage -> done (or cancelled):
// - Assignment: the free robot with the least expected travel time to the picker over the picker's belief,
//   E[T_r] = sum_n m(n) d(node_r, n) / robot_speed (d: shortest path length on the map), not only to its MAP
//   node. Calls are served in the order they came.
// - Target: the node of the belief's support with the least expected path length to the picker,
//   argmin_t sum_n m(n) d(t, n) (the belief's 1-median on the graph). With the belief in one lane that is the
//   lane's mass centre. Re-chosen at every update as the belief changes on the way (the robot's own LiDAR /
//   RFID sightings, a lane it saw empty).
// - Committing to a lane: while that lane holds less than commit_share of the belief, the robot is sent to
//   the end of a lane carrying mass with the least expected path to the picker, not into a lane (a robot in
//   the wrong lane must back out and go round). It waits there at most commit_wait s, then goes in.
// - Arrival only from the serving robot's own sensing: a sighting of that picker (an identified LiDAR
//   person or an RFID read of the picker's tag) within arrival_distance of the robot. Reaching the target
//   node is not arrival.
// - Loading: the robot waits load_time at the picker, then drives to storage_node; reaching it is done, and
//   the robot is free again.
// Time is the stamps given (message time), never the wall clock.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "picker_localisation/topology/topological_map.h"

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace dispatch {

enum class CallState { kQueued, kAssigned, kOnTheWay, kArrived, kToStorage, kDone, kCancelled };
const char* toString(CallState state);

struct DispatcherOptions {
  double robot_speed = 1.0;       // m/s along the graph, for the expected travel time
  // m: a sighting of the picker by the serving robot within this is arrival (2 m gave 11 of 224 arrivals more
  // than 3 m from the picker in the call scenario, 1.5 m with -48 dBm gave 3 for 7 % longer waits).
  double arrival_distance = 1.5;
  double load_time = 60.0;        // s the robot stays at the picker while the trays are loaded
  // dBm: a read of the picker's tag at least this strong is arrival. A read alone says only "within ~5 m"
  // (the logistic read model's d50 is 4 m); with free-space loss from -45 dBm at 1 m, -48 dBm is about 1.4 m.
  double arrival_min_rssi = -48.0;
  // An identified LiDAR person within arrival_distance is arrival too (measured: off, arrivals took 14 %
  // longer and as many were false; docs/readme/dispatch.md).
  bool arrival_by_lidar = true;
  // An identified LiDAR person is arrival only when the association named it at least this probably
  // (gnss_ingest names a person from association_min_probability, 0.8). Measured (docs/readme/dispatch.md,
  // "Arrival needs a surer name"): 0.85 halved the false arrivals at no measurable cost; 0.9 removed them on
  // Riseholme but made calls 0.7 s longer and entered more wrong lanes.
  double arrival_min_probability = 0.85;
  // The target's lane must hold this share of the belief before the robot enters it (0: always enters).
  // Measured with the planner positioning idle robots (docs/readme/dispatch.md, "Committing to a lane,
  // again"): 0.9 gave shorter waits and fewer wrong-lane entries than 0 on every farm tried.
  double commit_share = 0.9;
  double commit_wait = 60.0;  // s a robot waits at a lane end for the belief to commit, then enters anyway
  std::string storage_node;   // map node where full trays go ("": the robot stays where it loaded)

  std::string validate() const;  // "" or "<key> = <value>: must be ..."
  static DispatcherOptions fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();
};

struct Call {
  std::uint64_t id = 0;
  std::string picker_id;
  double stamp = 0.0;  // when the picker called
  CallState state = CallState::kQueued;
  std::string robot_id;                                 // the serving robot ("" while queued)
  topology::NodeIndex target = topology::kInvalidNode;  // where that robot is sent now
  double assigned_at = std::numeric_limits<double>::quiet_NaN();
  double arrived_at = std::numeric_limits<double>::quiet_NaN();
  double loaded_at = std::numeric_limits<double>::quiet_NaN();
  double holding_since = std::numeric_limits<double>::quiet_NaN();  // the robot waits at a lane end since
  double hold_ended = std::numeric_limits<double>::quiet_NaN();     // ... until it was sent into the lane
  double done_at = std::numeric_limits<double>::quiet_NaN();
  bool open() const { return state != CallState::kDone && state != CallState::kCancelled; }
};

// A new goal for a robot (a call's target, or the storage node).
struct Goal {
  std::string robot_id;
  topology::NodeIndex node = topology::kInvalidNode;
  std::uint64_t call_id = 0;
  CallState state = CallState::kAssigned;  // the call's state the goal belongs to
};

// One call as a line of a farm's call log (CSV; times are the stamps given, s; empty: not reached):
// callLogHeader() names the columns. The node's `calls_log` file and the live-graph benchmark read it.
std::string callLogHeader();
std::string callLogLine(const Call& call, const topology::TopologicalMap& map);

// The storage node a farm without one configured gets: the node outside every lane nearest the map's
// lower-left corner ("" for a map whose nodes are all in lanes). The runner and the dispatcher node alike.
std::string defaultStorageNode(const topology::TopologicalMap& map);

class CallDispatcher {
 public:
  // Throws std::invalid_argument on invalid options, a null map, an unknown storage node or no robot.
  CallDispatcher(std::shared_ptr<const topology::TopologicalMap> map, DispatcherOptions options,
                 std::vector<std::string> robot_ids);

  // A call of `picker_id` at `stamp`. Refused (nullopt, *error) for an empty id or a picker whose previous
  // call is still open; otherwise queued, and its id returned.
  std::optional<std::uint64_t> call(const std::string& picker_id, double stamp, std::string* error = nullptr);
  // Cancels an open call (its robot is free again). False, *error, for an unknown or closed call.
  bool cancel(std::uint64_t call_id, double stamp, std::string* error = nullptr);
  // The picker's belief as its tracker publishes it: nodes and masses (normalised here). An empty or
  // unusable belief is ignored (false).
  bool setBelief(const std::string& picker_id, const std::vector<topology::NodeIndex>& nodes,
                 const std::vector<double>& masses);
  // Where a robot is: its current node (the node it stands on or drives to). False for an unknown robot.
  bool setRobotNode(const std::string& robot_id, topology::NodeIndex node);
  // The robot's own sensing placed `picker_id` `distance` m from it at `stamp`. Arrival when that robot
  // serves the picker's open call, is on its way and distance <= arrival_distance. Returns whether it was an
  // arrival.
  bool sighting(const std::string& robot_id, const std::string& picker_id, double stamp, double distance);
  // A read of the picker's tag by one of the robot's antennas: arrival as sighting() when rssi >=
  // arrival_min_rssi (the read was close).
  bool rfidRead(const std::string& robot_id, const std::string& picker_id, double stamp, double rssi);
  // A person the robot's LiDAR saw, identified as `picker_id` by the association, `distance` m from the
  // robot: arrival as sighting() when arrival_by_lidar.
  bool lidarPerson(const std::string& robot_id, const std::string& picker_id, double stamp, double distance,
                   double probability = 1.0);
  // Assigns queued calls, re-targets, ends loading, ends deliveries; returns the goals that changed.
  std::vector<Goal> update(double now);

  const std::vector<Call>& calls() const { return calls_; }
  const Call* find(std::uint64_t call_id) const;
  // The open call a robot serves (nullptr: free; the planner may position it).
  const Call* servedBy(const std::string& robot_id) const;
  const std::vector<std::string>& robots() const { return robot_ids_; }
  // sum_n m(n) d(from, n) over the picker's belief, m; +inf without a belief or when unreachable.
  double expectedDistance(topology::NodeIndex from, const std::string& picker_id) const;
  // The node of the picker's belief with the least expected path length to the picker (kInvalidNode: none).
  topology::NodeIndex target(const std::string& picker_id) const;
  // Where the serving robot of `call` goes now: target(), or a lane end while the belief has not committed.
  topology::NodeIndex goalFor(Call& call, double now) const;
  const DispatcherOptions& options() const { return options_; }
  const topology::TopologicalMap& map() const { return *map_; }
  // A new version of the map (edited at run time): targets, robots' nodes and beliefs move to the new map's
  // node of the same name, else the nearest (change.old_to_new); the storage node is looked up again by name.
  // Throws std::invalid_argument, changing nothing, for an empty map, a map without the storage node or a
  // change that does not fit the current map.
  void adoptMap(std::shared_ptr<const topology::TopologicalMap> map, const topology::MapChange& change);

 private:
  struct Belief {
    std::vector<topology::NodeIndex> nodes;
    std::vector<double> masses;
  };
  Call* findOpen(std::uint64_t call_id);
  bool laneEnd(topology::NodeIndex n) const;  // a lane's node with a neighbour outside that lane
  // Shortest path lengths from a node (Dijkstra over the undirected motion graph), cached per source.
  const std::vector<double>& distancesFrom(topology::NodeIndex source) const;

  std::shared_ptr<const topology::TopologicalMap> map_;
  DispatcherOptions options_;
  std::vector<std::string> robot_ids_;
  topology::NodeIndex storage_ = topology::kInvalidNode;
  std::map<std::string, topology::NodeIndex> robot_node_;
  std::map<std::string, Belief> beliefs_;
  std::vector<Call> calls_;
  std::uint64_t next_id_ = 1;
  mutable std::map<topology::NodeIndex, std::vector<double>> distances_;
};

}  // namespace dispatch
}  // namespace picker_localisation
