// The leg_detector node's options: its own keys, the shared node keys (core::CommonNodeOptions) and the
// pipeline's (config/vision.yaml's leg_detector section, vision::LegPipelineOptions, shared with the runner).
// ROS-free, so the config test loads the shipped file through it.
#pragma once

#include <string>
#include <vector>

#include "picker_localisation/core/node_options.h"
#include "picker_localisation/sensors_vision/leg_pipeline.h"

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace vision {

struct LegDetectorNodeOptions {
  core::CommonNodeOptions common = defaultCommon();  // map_frame: the fixed frame people are placed in
  std::string robot_id;                              // Observation::robot_id ("" none)
  std::string model_file;            // OpenCV boosted classifier ("" the shipped config/leg_classifier.yml)
  bool publish_observations = true;  // people as Observations on observations_topic (needs the map)
  std::vector<std::string> scan_topics{"scan"};  // sensor_msgs/LaserScan inputs
  std::string cloud_topic;                       // sensor_msgs/PointCloud2 of a 3D LiDAR ("" none)
  std::string detections_topic;   // BearingDetectionArray of camera_detector ("" no camera fusion)
  std::string camera_info_topic;  // the camera's CameraInfo (its horizontal field of view)
  double fusion_max_age = 0.5;    // s: older camera detections are not fused
  int max_beams = 20000;          // larger scans are dropped (0: any size)
  LegPipelineOptions pipeline;    // the pipeline's keys

  static core::CommonNodeOptions defaultCommon();  // tf_timeout 0.1 s
  std::string validate() const;                    // "" or "<key> = <value>: must be ..."
  // Throws std::runtime_error naming the key on a bad value; *messages gets one line per unknown key and per
  // deprecated name.
  static LegDetectorNodeOptions fromYaml(const YAML::Node& node,
                                         std::vector<std::string>* messages = nullptr);
  // The leg_detector sections of the files, later files winning key by key (config/vision.yaml, then
  // vision_sim.yaml for the simulator).
  static LegDetectorNodeOptions fromYamlFiles(const std::vector<std::string>& files,
                                              std::vector<std::string>* messages = nullptr);
  static const std::vector<std::string>& yamlKeys();  // the node's own keys (its page's table)
};

}  // namespace vision
}  // namespace picker_localisation
