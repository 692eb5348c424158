// The gnss_ingest node's ROS adapter (see ranging_nodes.h for what the ranging front-ends share).
#pragma once

#include "picker_localisation/ros/ranging_nodes.h"
#include "picker_localisation/sensors_ranging/ranging_node_options.h"

namespace picker_localisation {
namespace ros_adapter {

// gnss_ingest: one NavSatFix subscription per picker (config/pickers.yaml gnss_topic). It follows the
// tracker's picker list (~registry_topic, latched PickerList, default /pickers/registry): a picker added to or
// removed from tpf_tracker at run time gets its fixes ingested or dropped; before a list arrives (or with
// ~registry_topic "") the ~pickers_file is the list.
// It also gives identity to anonymous people: Observations from every robot's leg_detector on
// ~person_observation_topic are associated with the pickers (sensors::associatePerson, against each picker's
// bias-corrected fix and its belief from the tracker's stream ~belief_topic, /pickers/beliefs); a clear association is published as
// an identifying observation of that picker and is a sighting for its GNSS bias estimate, an ambiguous one is
// published unchanged. With ~ordering_latency > 0 (automatic: 0.2 s under /use_sim_time) fixes and people are
// processed in stamp order, beliefs chosen by stamp (association_belief_lag), so a replayed bag gives the same
// output twice; live (0) each message is processed on arrival. Publishes the bias per picker
// (/pickers/<id>/gnss_bias, GnssBias; above ~on_demand_topics_above pickers only while someone subscribes, as
// tpf_tracker's topics) and rviz markers (~bias_markers: raw fix -> corrected fix).
class GnssIngestNode {
 public:
  GnssIngestNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  bool ok() const { return ok_; }

 private:
  // One picker with a GNSS device: its subscription and bias topic (its ingest and the tracker's recent
  // beliefs are the fleet's).
  struct Picker {
    Picker(const core::PickerConfig& config, sensors::GnssFleet::Picker* core) : config(config), core(core) {}
    core::PickerConfig config;
    sensors::GnssFleet::Picker* core;
    ros::Subscriber fix_sub;
    LastValuePublisher<picker_localisation::GnssBias> bias_pub;
    std::string bias_topic;  // resolved name
  };
  struct Input {
    bool is_fix = true;
    bool is_sighting = false;  // an identifying RFID / UWB observation (bias_sighting_sensors)
    std::string picker;        // the fix's picker (looked up on release: it may have been removed meanwhile)
    core::GnssFix fix;
    core::Observation person;
  };
  // Subscribes the picker's GNSS topic; false (a warning, nothing kept) when it cannot.
  bool addPicker(const core::PickerConfig& p);
  void advertiseBias(Picker& p);
  void onRegistry(const core::PickerRegistry& registry);
  void onFix(const sensor_msgs::NavSatFix::ConstPtr& msg, Picker* picker);
  void onPerson(const picker_localisation::Observation::ConstPtr& msg);
  // Anonymous people of other detectors (geometry_msgs/PoseArray in the map frame, as bayes_people_tracker
  // publishes) and picker positions already in the map frame (PoseWithCovarianceStamped per picker, e.g. from a
  // phone app's server): observations like any other sensor's.
  void onPeoplePoses(const geometry_msgs::PoseArray::ConstPtr& msg, const std::string& topic);
  void onPickerPose(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& msg, const std::string& picker);
  void followPoseTopics(const std::vector<std::string>& ids);
  // A person observation (ours or converted) into the association, in stamp order when ordering.
  void acceptPerson(core::Observation person, const std::string& key);
  bool inMapFrame(const std::string& frame, const char* what);
  void onIdentified(const picker_localisation::Observation::ConstPtr& msg);
  // An identifying observation of the fleet: a bias sighting (bias_sighting_sensors) and / or identity
  // evidence for the association (association_identity_sensors).
  void useIdentified(const core::Observation& obs);
  void onBelief(const picker_localisation::PickerBelief& msg);
  bool checkClock();
  // A new map from the map topic (MapFollower): every picker's ingest, and the datum when the map's moved.
  void adoptMap(std::shared_ptr<const topology::TopologicalMap> map, const topology::MapChange& change);
  bool loadDatum();
  void subscribePeople(ros::NodeHandle& nh, const sensors::GnssIngestNodeOptions& node_options,
                       const core::PickerRegistry& registry);
  void releaseOrdered();
  void processFix(Picker& picker, const core::GnssFix& fix);
  void processPerson(const core::Observation& person);
  void processPeople(const std::vector<core::Observation>& people);  // one robot sensor's, one stamp: jointly
  void publishBias(Picker& picker, double stamp, const sensors::GnssResult& r);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  bool ok_ = false;
  ros::NodeHandle nh_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<core::GeodeticDatum> datum_;
  std::string datum_file_, datum_source_;  // ~datum_file, ~datum_source (a new map's datum follows them)
  std::unique_ptr<MapFollower> map_follower_;
  std::string frame_id_, bias_prefix_;
  sensors::GnssIngestOptions options_;
  std::unique_ptr<sensors::GnssFleet>
      fleet_;  // every picker's ingest, the association, the identity evidence
  std::vector<std::unique_ptr<Picker>> pickers_;  // in the order of the list
  std::unordered_map<std::string, Picker*> by_id_;
  std::vector<ros::Subscriber> subs_;
  std::unique_ptr<FleetBeliefs> beliefs_;  // the trackers' beliefs (association_belief_weight > 0)
  ros::Publisher pub_;
  CountedPublisher markers_pub_;
  core::StampOrderedBuffer<Input> ordering_;
  double ordering_latency_ = 0.0;
  ros::Timer ordering_timer_;
  NodeDiagnostics diagnostics_;
  std::size_t published_ = 0, bad_people_ = 0, registry_updates_ = 0;
  std::size_t picker_poses_ = 0, bad_poses_ = 0, people_arrays_refused_ = 0, bad_beliefs_ = 0,
              pickers_refused_ = 0;
  std::size_t max_people_per_message_ = 100;  // ~max_people_per_message: a larger PoseArray is refused whole
  std::string people_pose_sensor_ = "people", pose_sensor_ = "pose", pose_topic_format_;
  double people_pose_sigma_ = 0.3;
  std::map<std::string, ros::Subscriber> pose_subs_;  // picker id -> its PoseWithCovarianceStamped topic
  StampGuard stamp_guard_;
  SilenceWatch silence_;
  OnDemandTopics on_demand_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
