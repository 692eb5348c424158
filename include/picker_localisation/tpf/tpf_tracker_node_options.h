// The tpf_tracker node's options: its own keys, the shared node keys (core::CommonNodeOptions), the fleet
// helpers' keys it uses, and the filter's (config/tpf.yaml, tpf::TpfParams: the base every picker's filter is
// built from, a picker's own overrides on top). ROS-free, so the config test loads the shipped files through
// it.
#pragma once

#include <string>
#include <vector>

#include "picker_localisation/core/node_options.h"
#include "picker_localisation/tpf/tpf_params.h"

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace tpf {

struct TpfTrackerNodeOptions {
  core::CommonNodeOptions common;  // ordering_latency < 0: 0.5 s
  core::FleetTopicOptions fleet;   // pickers_file, on_demand_topics_above, demand_poll_period
  std::string picker_id;           // one picker without a pickers file (tools, tests)
  std::string tpf_params_file;     // config/tpf.yaml; the node's parameters override its keys
  int seed = 0;  // > 0: every picker's filter seeded from it and the picker id; 0: from the id
  std::string topic_prefix =
      "/pickers";  // <prefix>/<id>/belief, estimate, markers; <prefix>/beliefs, registry
  // LCAS coordination's <namespace>/<id>/current_node ("/" gives /<id>/current_node; "" none);
  // "{topic_prefix}" is the prefix.
  std::string current_node_namespace = "{topic_prefix}";
  TpfParams tpf;  // the filter's keys (the base of every picker)

  std::string currentNodeNamespace() const;
  std::string validate() const;  // "" or "<key> = <value>: must be ..."
  // Throws std::runtime_error "tpf_tracker: <problem>" on a bad value; *messages gets one line per unknown
  // key and per deprecated name.
  static TpfTrackerNodeOptions fromYaml(const YAML::Node& node, std::vector<std::string>* messages = nullptr);
  static const std::vector<std::string>& yamlKeys();  // the node's own and fleet keys (its page's table)
  // Every key that is not the filter's: what the node removes before building the filters' base.
  static std::vector<std::string> nodeKeys();
};

}  // namespace tpf
}  // namespace picker_localisation
