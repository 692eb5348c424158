#include "picker_localisation/sensors_vision/leg_detector_node_options.h"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "picker_localisation/core/option_table.h"

namespace picker_localisation {
namespace vision {

namespace {

const char* kComponent = "leg_detector";

const core::OptionTable<LegDetectorNodeOptions>& table() {
  using O = LegDetectorNodeOptions;
  static const core::OptionTable<O> t = core::OptionTable<O>()
                                            .add("robot_id", &O::robot_id)
                                            .add("model_file", &O::model_file)
                                            .add("publish_observations", &O::publish_observations)
                                            .add("scan_topics", &O::scan_topics)
                                            .add("cloud_topic", &O::cloud_topic)
                                            .add("detections_topic", &O::detections_topic)
                                            .add("camera_info_topic", &O::camera_info_topic)
                                            .add("fusion_max_age", &O::fusion_max_age)
                                            .add("max_beams", &O::max_beams);
  return t;
}

}  // namespace

core::CommonNodeOptions LegDetectorNodeOptions::defaultCommon() {
  core::CommonNodeOptions c;
  c.tf_timeout = 0.1;
  return c;
}

std::string LegDetectorNodeOptions::validate() const {
  std::string problem = common.validate();
  if (!problem.empty()) return problem;
  if (!(fusion_max_age > 0.0) || !std::isfinite(fusion_max_age))
    return core::badValue("fusion_max_age", fusion_max_age, "finite and > 0");
  if (max_beams < 0) return core::badValue("max_beams", max_beams, ">= 0 (0: any size)");
  return pipeline.validate();
}

const std::vector<std::string>& LegDetectorNodeOptions::yamlKeys() {
  return table().keys();
}

LegDetectorNodeOptions LegDetectorNodeOptions::fromYaml(const YAML::Node& node,
                                                        std::vector<std::string>* messages) {
  LegDetectorNodeOptions o;
  o.common = core::CommonNodeOptions::fromYaml(node, kComponent, messages, o.common);
  table().read(node, kComponent, o);
  o.pipeline = LegPipelineOptions::fromYaml(node);
  return core::checkOptions(
      o, node,
      core::joinKeys({yamlKeys(), core::CommonNodeOptions::acceptedKeys(), LegPipelineOptions::yamlKeys()}),
      kComponent, messages);
}

LegDetectorNodeOptions LegDetectorNodeOptions::fromYamlFiles(const std::vector<std::string>& files,
                                                             std::vector<std::string>* messages) {
  return fromYaml(LegPipelineOptions::mergedSections(files), messages);
}

}  // namespace vision
}  // namespace picker_localisation
