// The options of the GNSS, RFID and UWB front-end nodes: each node's own keys, the shared node keys
// (core::CommonNodeOptions), the fleet helpers' keys it uses (core::FleetTopicOptions) and the algorithm's
// options (the same struct the offline runner builds), read from one YAML map: the node's private parameters
// or its config file. ROS-free, so the config test loads every shipped file through them.
#pragma once

#include <string>
#include <vector>

#include "picker_localisation/core/node_options.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "picker_localisation/sensors_ranging/rfid_observation_model.h"
#include "picker_localisation/sensors_ranging/uwb_ranging.h"

namespace YAML {
class Node;
}

namespace picker_localisation {
namespace sensors {

struct GnssIngestNodeOptions {
  core::CommonNodeOptions common;  // map_frame, observations_topic, ordering_latency (< 0: 0.2 s), ...
  core::FleetTopicOptions
      fleet;  // pickers_file (required by the node), registry, beliefs, on-demand topics, silence
  std::string datum_file;             // config/datum.yaml format; required when the map has no datum
  std::string datum_source = "auto";  // auto (the map's datum when it has one) | file | map
  std::string person_observation_topic = "/person_observations";  // anonymous people in ("" none)
  std::string bias_topic_prefix = "/pickers";   // <prefix>/<id>/gnss_bias (GnssBias, latched)
  std::vector<std::string> people_pose_topics;  // geometry_msgs/PoseArray of people in the map frame
  std::string people_pose_sensor = "people";    // Observation::sensor of those people
  double people_pose_sigma = 0.3;               // m, per axis, of those people
  std::string pose_topic_format;     // "" none; e.g. "/{id}/pose": a picker's own map-frame position
  std::string pose_sensor = "pose";  // Observation::sensor of those positions
  int max_people_per_message = 100;  // a larger PoseArray is refused whole
  GnssIngestOptions ingest;          // config/gnss_ingest.yaml (shared with the runner)

  std::string validate() const;  // "" or "<key> = <value>: must be ..."
  // Throws std::runtime_error "gnss_ingest: <problem>" on a bad value; *messages gets one line per unknown
  // key (the closest known one named) and per deprecated name.
  static GnssIngestNodeOptions fromYaml(const YAML::Node& node, std::vector<std::string>* messages = nullptr);
  static GnssIngestNodeOptions fromYamlFile(const std::string& path,
                                            std::vector<std::string>* messages = nullptr);
  static const std::vector<std::string>& yamlKeys();  // the node's own and fleet keys (its page's table)
};

struct RfidRangingNodeOptions {
  core::CommonNodeOptions common;
  core::FleetTopicOptions fleet;                 // pickers_file (required by the node), registry, silence
  std::vector<std::string> rfid_topics{"rfid"};  // RfidReading inputs, one per reader
  RfidModelOptions model;                        // config/rfid_ranging.yaml (shared with the runner)

  std::string validate() const;
  static RfidRangingNodeOptions fromYaml(const YAML::Node& node,
                                         std::vector<std::string>* messages = nullptr);
  static RfidRangingNodeOptions fromYamlFile(const std::string& path,
                                             std::vector<std::string>* messages = nullptr);
  static const std::vector<std::string>& yamlKeys();
};

struct UwbRangingNodeOptions {
  core::CommonNodeOptions common;
  core::FleetTopicOptions fleet;               // pickers_file (required by the node), registry, silence
  std::string base_frame;                      // the robot's frame ("" the messages' frame_id)
  std::vector<std::string> uwb_topics{"uwb"};  // UwbRange inputs
  std::vector<std::string> bearing_topics;     // CameraBearing inputs (the RHF's camera gate)
  double flush_period = 0.05;                  // s of wall time between emitting the batched beliefs
  UwbRangingOptions ranging;                   // config/uwb_ranging.yaml (shared with the runner)

  std::string validate() const;
  static UwbRangingNodeOptions fromYaml(const YAML::Node& node, std::vector<std::string>* messages = nullptr);
  static UwbRangingNodeOptions fromYamlFile(const std::string& path,
                                            std::vector<std::string>* messages = nullptr);
  static const std::vector<std::string>& yamlKeys();
};

}  // namespace sensors
}  // namespace picker_localisation
