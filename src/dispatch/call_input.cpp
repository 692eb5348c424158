#include "picker_localisation/dispatch/call_input.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

namespace picker_localisation {
namespace dispatch {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string fixed(double v, int digits) {
  std::ostringstream out;
  out.precision(digits);
  out << std::fixed << v;
  return out.str();
}

}  // namespace

std::optional<CallInput> parseCarMessage(const std::string& text, std::string* error) {
  auto refuse = [error](const std::string& why) -> std::optional<CallInput> {
    if (error) *error = why;
    return std::nullopt;
  };
  YAML::Node node;
  try {
    node = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return refuse("not JSON: " + e.msg);
  }
  if (!node.IsMap()) return refuse("not a JSON object");
  CallInput call;
  try {
    if (!node["user"] || !node["user"].IsScalar() || node["user"].as<std::string>().empty())
      return refuse("no \"user\" (the picker's id)");
    call.picker_id = node["user"].as<std::string>();
    const bool has_lat = node["lat"] && !node["lat"].IsNull();
    const bool has_lon = node["long"] && !node["long"].IsNull();
    if (has_lat != has_lon) return refuse("\"lat\" without \"long\" or the other way round");
    if (has_lat) {
      call.has_fix = true;
      call.latitude = node["lat"].as<double>();
      call.longitude = node["long"].as<double>();
    }
    if (node["row"] && !node["row"].IsNull()) {
      if (!node["row"].IsScalar()) return refuse("\"row\" is not a string or number");
      call.row = node["row"].as<std::string>();
    }
    if (node["state"] && node["state"].IsScalar()) {
      const std::string state = lower(node["state"].as<std::string>());
      call.cancel = state == "cancel" || state == "cancelled" || state == "canceled" || state == "init";
    }
  } catch (const YAML::Exception&) {
    return refuse("\"lat\" and \"long\" must be numbers");
  }
  return call;
}

CheckedCall checkCall(const CallInput& call, const topology::TopologicalMap& map,
                      const core::GeodeticDatum* datum, double max_fix_distance) {
  CheckedCall out;
  std::string note;
  auto add = [&note](const std::string& s) { note += (note.empty() ? "" : "; ") + s; };
  if (call.has_fix) {
    if (!std::isfinite(call.latitude) || !std::isfinite(call.longitude) || std::abs(call.latitude) > 90.0 ||
        std::abs(call.longitude) > 180.0) {
      add("fix (" + fixed(call.latitude, 7) + ", " + fixed(call.longitude, 7) +
          ") is not a WGS84 position; left out");
    } else if (!datum) {
      add("fix left out: no datum to place it on the map");
    } else {
      const Eigen::Vector2d p = datum->toMap(call.latitude, call.longitude);
      const double off = map.distanceToNearestNode(p);
      if (!(off <= max_fix_distance))
        add("fix is " + fixed(off, 0) + " m from the nearest node (more than max_fix_distance " +
            fixed(max_fix_distance, 0) + " m): off the map; left out");
      else
        out.fix = p;
    }
  }
  if (!call.row.empty()) {
    const auto& names = map.laneNames();
    for (std::size_t l = 0; l < names.size() && out.row_lane == topology::kNoLane; ++l)
      if (names[l] == call.row || names[l] == "row_" + call.row)
        out.row_lane = static_cast<topology::LaneIndex>(l);
    if (out.row_lane == topology::kNoLane)
      add("row '" + call.row + "' is not a lane of the map (" + std::to_string(names.size()) +
          " lanes); left out");
  }
  out.note = note;
  return out;
}

core::Observation reportedRowObservation(const topology::TopologicalMap& map, topology::LaneIndex lane,
                                         const std::string& picker_id, double stamp, double floor) {
  core::Observation obs;
  if (lane == topology::kNoLane) return obs;
  obs.stamp = stamp;
  obs.sensor = "reported_row";
  obs.picker_id = picker_id;
  obs.identifying = true;
  obs.nodes.reserve(map.numNodes());
  obs.likelihood.reserve(map.numNodes());
  for (topology::NodeIndex n = 0; n < map.numNodes(); ++n) {
    obs.nodes.push_back(n);
    obs.likelihood.push_back(map.lane(n) == lane ? 1.0 : floor);
  }
  return obs;
}

}  // namespace dispatch
}  // namespace picker_localisation
