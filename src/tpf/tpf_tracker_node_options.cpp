#include "picker_localisation/tpf/tpf_tracker_node_options.h"

#include <yaml-cpp/yaml.h>

#include "picker_localisation/core/option_table.h"

namespace picker_localisation {
namespace tpf {

namespace {

const char* kComponent = "tpf_tracker";
// Not a parameter: gnss_ingest's namespace when it runs inside the tracker's process
// (launch/trackers.launch).
const char* kGnssIngestNamespace = "gnss_ingest";

const core::OptionTable<TpfTrackerNodeOptions>& table() {
  using O = TpfTrackerNodeOptions;
  using F = core::FleetTopicOptions;
  static const core::OptionTable<O> t =
      core::OptionTable<O>()
          .add("pickers_file", &O::fleet, &F::pickers_file)
          .add("picker_id", &O::picker_id)
          .add("tpf_params_file", &O::tpf_params_file)
          .add("seed", &O::seed)
          .add("topic_prefix", &O::topic_prefix)
          .add("current_node_namespace", &O::current_node_namespace)
          .add("on_demand_topics_above", &O::fleet, &F::on_demand_topics_above)
          .add("demand_poll_period", &O::fleet, &F::demand_poll_period);
  return t;
}

}  // namespace

std::string TpfTrackerNodeOptions::currentNodeNamespace() const {
  return current_node_namespace == "{topic_prefix}" ? topic_prefix : current_node_namespace;
}

std::string TpfTrackerNodeOptions::validate() const {
  std::string problem = common.validate();
  if (problem.empty()) problem = fleet.validate();
  if (!problem.empty()) return problem;
  if (seed < 0) return core::badValue("seed", seed, ">= 0");
  if (topic_prefix.empty()) return "topic_prefix: must not be empty";
  return tpf.validate();
}

const std::vector<std::string>& TpfTrackerNodeOptions::yamlKeys() {
  return table().keys();
}

std::vector<std::string> TpfTrackerNodeOptions::nodeKeys() {
  return core::joinKeys({yamlKeys(), core::CommonNodeOptions::acceptedKeys(), {kGnssIngestNamespace}});
}

TpfTrackerNodeOptions TpfTrackerNodeOptions::fromYaml(const YAML::Node& node,
                                                      std::vector<std::string>* messages) {
  TpfTrackerNodeOptions o;
  o.common = core::CommonNodeOptions::fromYaml(node, kComponent, messages, o.common);
  table().read(node, kComponent, o);
  YAML::Node filter_keys = YAML::Clone(node);
  if (filter_keys.IsMap())
    for (const std::string& k : nodeKeys()) filter_keys.remove(k);
  o.tpf = TpfParams::fromYaml(filter_keys);
  return core::checkOptions(o, node, core::joinKeys({nodeKeys(), TpfParams::yamlKeys()}), kComponent,
                            messages);
}

}  // namespace tpf
}  // namespace picker_localisation
