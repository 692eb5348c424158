// The parameters every node of the suite shares, under one name each: the map frame, the observations topic,
// the stamp checks, tf and the map source. Read by each node next to its own options (ROS-free, so the config
// test loads it). The names used before (frame_id, fixed_frame, observation_topic) are still read for one
// release, each with a deprecation warning.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace core {

struct CommonNodeOptions {
  std::string map_frame = "map";                     // frame of maps, observations and beliefs (REP 105)
  std::string observations_topic = "/observations";  // core::Observation stream (Observation messages)
  double max_future_stamp = 10.0;  // s: a stamp further ahead of the clock is refused (0: any)
  double tf_timeout = 0.2;         // s to wait for a transform
  double ordering_latency = -1.0;  // s inputs are held to be fused in stamp order (< 0: the node's default)
  std::string map_file;            // tmap2 / tmap file ("": the latched map topic)
  std::string
      map_topic;  // the map topic ("": the global /map_topic, else /picker_localisation/topological_map)
  double map_timeout = 30.0;       // s to wait for the map topic at start-up (0: for ever)

  std::string validate() const;  // "" or "<key> = <value>: must be ..."
  static const std::vector<std::string>& yamlKeys();
  // {old name, name}: still read, with a warning, when the new name is not set.
  static const std::vector<std::pair<std::string, std::string>>& deprecatedKeys();
  // The keys of `node` over `defaults` (a node's own defaults). An old name adds one message to *warnings
  // ("<component>: parameter 'frame_id' is deprecated, use 'map_frame'"). Throws std::runtime_error
  // "<component>: <problem>" on a value of the wrong type or out of range.
  static CommonNodeOptions fromYaml(const YAML::Node& node, const std::string& component,
                                    std::vector<std::string>* warnings, CommonNodeOptions defaults);
  // yamlKeys() and the old names: what a node's unknown-key check accepts besides its own keys.
  static std::vector<std::string> acceptedKeys();
};

// The keys of the helpers several nodes share: the picker list, the tracker's list and belief stream, topics
// advertised on demand, the silence watch. Each node's options table lists the ones it uses.
struct FleetTopicOptions {
  std::string pickers_file;                          // config/pickers.yaml format
  std::string registry_topic = "/pickers/registry";  // the tracker's latched picker list ("" not followed)
  std::string registry_publisher = "/tpf_tracker";   // only this node's lists are followed ("" any)
  std::string belief_topic =
      "/pickers/beliefs";  // every picker's belief (PickerBeliefArray; "" each /pickers/<id>/belief)
  int on_demand_topics_above = 100;  // pickers: above this, per-picker topics while subscribed
  double demand_poll_period = 2.0;   // s between asking the master who subscribes (>= 0.2)
  double silent_warn_after = 30.0;   // s of silence on an input before diagnostics WARN (0 never)

  std::string validate() const;  // "" or "<key> = <value>: must be ..."
};

}  // namespace core
}  // namespace picker_localisation
