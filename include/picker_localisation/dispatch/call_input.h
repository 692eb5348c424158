// What a call brings besides the picker's id, checked before the dispatcher serves it (ROS-free, so the
// dispatcher node and the tests read calls alike).
// - The LCAS Call-A-Robot (CAR) app's message: JSON in a std_msgs/String, {"user": id, "lat": deg, "long":
// deg,
//   "row": name, "state": ...}. Only "user" is required; "state" CANCEL / CANCELLED / INIT (any case) cancels
//   the user's open call, anything else (CALLED, ...) calls; other fields are ignored. Parsed with yaml-cpp
//   (JSON is a subset of YAML 1.2), no second parser.
// - The optional parts (the phone's fix, the reported row) are checked against the map: a part that cannot be
//   used is left out with a note, the call itself is still served.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/core/observation.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace dispatch {

struct CallInput {
  std::string picker_id;
  bool has_fix = false;
  double latitude = 0.0, longitude = 0.0;  // WGS84 deg, when has_fix
  std::string row;                         // the row the picker reports ("" none)
  bool cancel = false;                     // the CAR app withdrew the call
};

// Parses one CAR message. nullopt and *error (one line) when it is not a JSON object, has no non-empty
// "user", or a field has the wrong type (lat / long not numbers, or only one of them).
std::optional<CallInput> parseCarMessage(const std::string& text, std::string* error = nullptr);

// The parts of a call the dispatcher can use.
struct CheckedCall {
  std::optional<Eigen::Vector2d> fix;                // map frame, m: the fix, when finite and on the map
  topology::LaneIndex row_lane = topology::kNoLane;  // the reported row's lane, when the map has it
  std::string note;                                  // what was left out and why ("" nothing)
};

// Checks the fix (finite, a datum to place it, within max_fix_distance m of a node) and the row (a lane of
// the map, by name; "3" also matches a lane named row_3). `datum` may be null (no datum: a fix is left out).
CheckedCall checkCall(const CallInput& call, const topology::TopologicalMap& map,
                      const core::GeodeticDatum* datum, double max_fix_distance);

// The reported row as evidence for the picker's filter, not a restriction (pickers mistype): an identifying
// observation (sensor "reported_row") over every node of the map, likelihood 1 on the lane's nodes and
// `floor` (in (0, 1)) elsewhere, so particles outside the row are down-weighted, never removed. Empty for
// kNoLane.
core::Observation reportedRowObservation(const topology::TopologicalMap& map, topology::LaneIndex lane,
                                         const std::string& picker_id, double stamp, double floor);

}  // namespace dispatch
}  // namespace picker_localisation
