#include "picker_localisation/ros/map_source.h"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/master.h>
#include <ros/topic.h>
#include <std_msgs/String.h>

#include <cstdint>
#include <optional>
#include <stdexcept>

#include "picker_localisation/ros/map_conversions.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/topology/map_io.h"

namespace picker_localisation {
namespace ros_adapter {

namespace {

// A node's map_file / map_topic, else the global /map_file, /map_topic (one setting a launch file gives every
// node): the only parameters read outside a node's options struct, as they are not the node's.
std::string ownOrGlobal(const std::string& own, const char* global) {
  std::string value = own;
  if (value.empty()) ros::param::get(global, value);
  return value;
}

}  // namespace

std::string mapTopic(ros::NodeHandle& nh, const core::CommonNodeOptions& common) {
  const std::string topic = ownOrGlobal(common.map_topic, "/map_topic");
  return nh.resolveName(topic.empty() ? std::string(kMapTopic) : topic);
}

std::optional<core::CommonNodeOptions> mapOptionsOf(const ros::NodeHandle& pnh) {
  try {
    return core::CommonNodeOptions::fromYaml(paramsAsYaml(pnh), ros::this_node::getName(), nullptr, {});
  } catch (const std::exception& e) {
    ROS_FATAL("%s", e.what());
    return std::nullopt;
  }
}

bool useMapDatum(const std::string& datum_source, const topology::TopologicalMap& map) {
  if (datum_source != "auto" && datum_source != "file" && datum_source != "map")
    throw std::runtime_error("~datum_source '" + datum_source + "' must be auto, file or map");
  if (datum_source == "map" && !map.datum())
    throw std::runtime_error("~datum_source is map but the map has no meta.datum_latitude");
  return datum_source == "map" || (datum_source == "auto" && map.datum());
}

namespace {

// The type the master knows for `topic` ("" while nobody advertises it).
std::string topicType(const std::string& topic) {
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return "";
  for (const auto& t : topics)
    if (t.name == topic) return t.datatype;
  return "";
}

// A map message that cannot be read is bad input, not a reason to stop: one ERROR line and a diagnostics
// ERROR ("<node>: map"), then the node waits for the next message. The node's own diagnostics updater does
// not exist yet (it needs the map), so the status goes out here.
class MapRefusals {
 public:
  MapRefusals(const ros::NodeHandle& nh, std::string node, std::string topic)
      : nh_(nh), node_(std::move(node)), topic_(std::move(topic)) {}

  // True when `fingerprint` is the message refused last (a latched topic delivers it again until replaced).
  bool alreadyRefused(const std::string& fingerprint) const {
    return fingerprint_ && fingerprint == *fingerprint_;
  }

  void refuse(const std::string& fingerprint, const std::string& why,
              const char* meanwhile = "waiting for a valid one") {
    fingerprint_ = fingerprint;
    last_error_ = why;
    ++count_;
    ROS_ERROR("%s: map message on %s refused, %s: %s", node_.c_str(), topic_.c_str(), meanwhile, why.c_str());
    report(diagnostic_msgs::DiagnosticStatus::ERROR, "map message on " + topic_ + " refused: " + why);
  }

  // After a refusal, the valid map taken clears the ERROR (OK, same status name).
  void taken(const topology::TopologicalMap& map) {
    if (!fingerprint_) return;
    fingerprint_.reset();
    ROS_INFO("%s: valid map '%s' on %s taken after the refused one", node_.c_str(), map.name().c_str(),
             topic_.c_str());
    report(diagnostic_msgs::DiagnosticStatus::OK, "map '" + map.name() + "' taken from " + topic_);
  }

  const std::string& lastError() const { return last_error_; }
  std::size_t count() const { return count_; }

 private:
  void report(std::uint8_t level, const std::string& message) {
    // Kept for the process's life (never destroyed: a publisher must not outlive roscpp's shutdown), so the
    // last status (latched) still reaches late subscribers after the map is taken and this object is gone.
    static ros::Publisher* const diag_pub =
        new ros::Publisher(nh_.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 1, true));
    diagnostic_msgs::DiagnosticArray array;
    array.header.stamp = ros::Time::now();
    diagnostic_msgs::DiagnosticStatus status;
    status.level = level;
    status.name = (node_.rfind('/', 0) == 0 ? node_.substr(1) : node_) + ": map";
    status.hardware_id = "none";
    status.message = message;
    array.status.push_back(status);
    diag_pub->publish(array);
  }

  ros::NodeHandle nh_;
  std::string node_, topic_;
  std::optional<std::string>
      fingerprint_;  // of the message refused last; none before any or after a valid one
  std::string last_error_;
  std::size_t count_ = 0;
};

// What tells two map messages apart cheaply enough (the text itself; the header and size of a map message).
std::string fingerprintOf(const std_msgs::String& m) {
  return m.data;
}
std::string fingerprintOf(const picker_localisation::TopologicalMap& m) {
  // The header and a hash (FNV-1a) of the content: a restarted server publishes seq 0 again, and under a
  // simulated clock that has not started every stamp is 0.
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) h = (h ^ static_cast<const unsigned char*>(data)[i]) * 1099511628211ull;
  };
  for (const auto& n : m.nodes) {
    mix(n.name.data(), n.name.size());
    mix(&n.pose.position.x, sizeof(double));
    mix(&n.pose.position.y, sizeof(double));
    mix(n.lane.data(), n.lane.size());
  }
  for (const auto& e : m.edges) {
    mix(&e.source, sizeof(e.source));
    mix(&e.target, sizeof(e.target));
  }
  mix(m.name.data(), m.name.size());
  return std::to_string(m.header.seq) + "/" + std::to_string(m.header.stamp.toNSec()) + "/" +
         std::to_string(m.nodes.size()) + "/" + std::to_string(h);
}

// The map a message holds, for start-up and later updates alike; throws topology::MapError when it holds none.
std::shared_ptr<const topology::TopologicalMap> mapOf(const std_msgs::String& m, const std::string& topic) {
  return std::make_shared<topology::TopologicalMap>(topology::parseMap(m.data, topic));
}
std::shared_ptr<const topology::TopologicalMap> mapOf(const picker_localisation::TopologicalMap& m,
                                                      const std::string&) {
  return std::make_shared<topology::TopologicalMap>(fromMsg(m));
}

// One message of type M from `topic`, turned into a map; nullptr when none came within a second, when it is
// the message refused last, or when it is refused now.
template <typename M>
std::shared_ptr<const topology::TopologicalMap> takeMap(const std::string& topic, ros::NodeHandle& nh,
                                                        MapRefusals& refusals) {
  const auto msg = ros::topic::waitForMessage<M>(topic, nh, ros::Duration(1.0));
  if (!msg) return nullptr;
  const std::string fingerprint = fingerprintOf(*msg);
  if (refusals.alreadyRefused(fingerprint)) {
    ros::WallDuration(0.2).sleep();
    return nullptr;
  }
  try {
    std::shared_ptr<const topology::TopologicalMap> map = mapOf(*msg, topic);
    refusals.taken(*map);
    return map;
  } catch (const topology::MapError& e) {
    refusals.refuse(fingerprint, e.what());
    return nullptr;
  }
}

}  // namespace

std::shared_ptr<const topology::TopologicalMap> obtainMap(ros::NodeHandle& nh,
                                                          const core::CommonNodeOptions& common) {
  const std::string name = ros::this_node::getName();
  const double timeout = common.map_timeout;
  const std::string map_file = ownOrGlobal(common.map_file, "/map_file");
  try {
    if (!map_file.empty()) return std::make_shared<topology::TopologicalMap>(topology::loadMap(map_file));
    const std::string topic = mapTopic(nh, common);
    ROS_INFO("%s: waiting for the topological map on %s", name.c_str(), topic.c_str());
    MapRefusals refusals(nh, name, topic);
    ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout > 0 ? timeout : 1e9);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      const std::string type = topicType(topic);
      std::shared_ptr<const topology::TopologicalMap> map;
      if (type == "picker_localisation/TopologicalMap") {
        map = takeMap<picker_localisation::TopologicalMap>(topic, nh, refusals);
      } else if (type == "std_msgs/String") {
        map = takeMap<std_msgs::String>(topic, nh, refusals);
        if (map)
          ROS_INFO("%s: map '%s' from %s (tmap2 text): %zu nodes, %zu lanes", name.c_str(), map->name().c_str(),
                   topic.c_str(), map->numNodes(), map->numLanes());
      } else if (!type.empty()) {
        ROS_FATAL(
            "%s: %s is a %s; a map topic must be picker_localisation/TopologicalMap (topological_map_server) "
            "or std_msgs/String holding a tmap2 document (LCAS: /topological_map_2)%s",
            name.c_str(), topic.c_str(), type.c_str(),
            type.rfind("topological_navigation_msgs/", 0) == 0 ? "; set map_topic:=/topological_map_2" : "");
        return nullptr;
      } else {
        ros::WallDuration(0.2).sleep();
      }
      if (map) return map;
    }
    if (refusals.lastError().empty())
      ROS_FATAL("%s: no topological map on %s within %.0f s and no ~map_file parameter", name.c_str(),
                topic.c_str(), timeout);
    else
      ROS_FATAL("%s: no valid topological map on %s within %.0f s (the last one was refused: %s)",
                name.c_str(), topic.c_str(), timeout, refusals.lastError().c_str());
  } catch (const topology::MapError& e) {
    ROS_FATAL("%s: %s", name.c_str(), e.what());
  }
  return nullptr;
}

struct MapFollower::Impl {
  Impl(ros::NodeHandle& nh, std::string node, std::string topic)
      : refusals(nh, node, topic), node(std::move(node)), topic(std::move(topic)) {}

  // One map message: nothing when it is the current one (or the one refused last), else refused or adopted.
  template <typename M>
  void onMessage(const M& msg) {
    std::string fingerprint = fingerprintOf(msg);
    if (fingerprint == current_fingerprint) {
      refusals.taken(*current);  // the current map re-sent after a refused one: the ERROR is over
      return;
    }
    if (refusals.alreadyRefused(fingerprint)) return;
    std::shared_ptr<const topology::TopologicalMap> map;
    try {
      map = mapOf(msg, topic);
    } catch (const std::exception& e) {  // topology::MapError, or anything else a conversion meets
      refusals.refuse(fingerprint, e.what(), "keeping the current map");
      return;
    }
    try {
      const topology::MapChange change = topology::compareMaps(*current, *map);
      if (!change.identical()) {  // else re-published unchanged (the latched message seen at subscription)
        ROS_INFO("%s: map updated: %s (map '%s' on %s, %zu nodes)", node.c_str(), change.summary().c_str(),
                 map->name().c_str(), topic.c_str(), map->numNodes());
        adopt(map, change);
        current = map;
        ++updates;
      }
      refusals.taken(*map);
      current_fingerprint = std::move(fingerprint);
    } catch (const std::exception& e) {  // nothing may end the node from a callback (std::bad_alloc)
      ROS_ERROR("%s: map on %s not adopted: %s", node.c_str(), topic.c_str(), e.what());
    }
  }

  MapRefusals refusals;
  std::string node, topic, current_fingerprint;
  std::shared_ptr<const topology::TopologicalMap> current;
  Adopt adopt;
  ros::Subscriber sub;
  std::size_t updates = 0;
};

MapFollower::MapFollower(ros::NodeHandle& nh, const core::CommonNodeOptions& common,
                         std::shared_ptr<const topology::TopologicalMap> current, Adopt adopt) {
  if (!ownOrGlobal(common.map_file, "/map_file").empty() || !current) return;
  const std::string topic = mapTopic(nh, common);
  impl_ = std::make_unique<Impl>(nh, ros::this_node::getName(), topic);
  impl_->current = std::move(current);
  impl_->adopt = std::move(adopt);
  Impl* impl = impl_.get();
  const std::string type = topicType(topic);
  if (type == "std_msgs/String") {
    impl_->sub = nh.subscribe<std_msgs::String>(
        topic, 1, [impl](const std_msgs::String::ConstPtr& m) { impl->onMessage(*m); });
  } else {  // the type obtainMap() read (topological_map_server's), also while nobody publishes
    impl_->sub = nh.subscribe<picker_localisation::TopologicalMap>(
        topic, 1, [impl](const picker_localisation::TopologicalMap::ConstPtr& m) { impl->onMessage(*m); });
  }
}

MapFollower::~MapFollower() = default;
bool MapFollower::following() const {
  return impl_ != nullptr;
}
std::size_t MapFollower::updates() const {
  return impl_ ? impl_->updates : 0;
}
std::size_t MapFollower::refusals() const {
  return impl_ ? impl_->refusals.count() : 0;
}

}  // namespace ros_adapter
}  // namespace picker_localisation
