// ROS adapters of the sensors_ranging front-ends (thin: parameters -> core objects, messages -> core types ->
// picker_localisation/Observation on /observations). Parameters and topics: docs/readme/sensors_ranging.md and
// config/gnss_ingest.yaml, config/rfid_ranging.yaml, config/uwb_ranging.yaml.
#pragma once

#include "picker_localisation/ros/node_diagnostics.h"
#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <picker_localisation/BearingDetectionArray.h>
#include <picker_localisation/GnssBias.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBeliefArray.h>
#include <picker_localisation/PickerList.h>
#include <picker_localisation/RfidReading.h>
#include <picker_localisation/UwbRange.h>
#include <ros/ros.h>
#include <sensor_msgs/NavSatFix.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/core/stamp_ordered_buffer.h"
#include "picker_localisation/ros/fleet_topics.h"
#include "picker_localisation/ros/last_value_publisher.h"
#include "picker_localisation/ros/stamp_guard.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "picker_localisation/sensors_ranging/picker_association.h"
#include "picker_localisation/sensors_ranging/rfid_observation_model.h"
#include "picker_localisation/sensors_ranging/uwb_ranging.h"

namespace picker_localisation {
namespace ros_adapter {

// sensor_msgs/NavSatFix -> core GnssFix (no checks: GnssIngest does them).
core::GnssFix gnssFixFromMsg(const sensor_msgs::NavSatFix& msg);
// A good fix (STATUS_FIX, diagonal covariance sigma^2 horizontally, (2 sigma)^2 vertically, altitude 50 m) at a
// map position, as a phone would send it (tests, bench_fleet).
sensor_msgs::NavSatFix navSatFixAt(const core::GeodeticDatum& datum, const Eigen::Vector2d& map_xy,
                                   const ros::Time& stamp, double sigma = 1.0);

// Looks up `target <- source` at `stamp`, waiting at most `timeout` s. nullopt (and *error set) when the
// transform is not available (unknown frame, extrapolation, empty frame id).
std::optional<Eigen::Isometry3d> lookupTransform(const tf2_ros::Buffer& buffer, const std::string& target,
                                                 const std::string& source, const ros::Time& stamp,
                                                 double timeout, std::string* error);
// The picker registry from the required ~pickers_file; nullopt after one ROS_FATAL line naming `node`.
std::optional<core::PickerRegistry> loadPickerRegistry(ros::NodeHandle& pnh, const char* node);
// A front-end's input that should be talking (a mistyped topic must not look green): once
// ~silent_warn_after s of ROS time (default 30; 0 = never) pass without a message, since the start or since the
// last one, the node's diagnostics go WARN naming the input and how long it has been quiet.
class SilenceWatch {
 public:
  void configure(ros::NodeHandle& pnh, std::string what);
  void heard();  // a message arrived
  // Adds "<what>: seconds since the last" and, when silent too long, merges a WARN into the summary.
  void report(diagnostic_updater::DiagnosticStatusWrapper& stat);

 private:
  std::string what_;
  double warn_after_ = 30.0;
  ros::Time start_, last_;
};

// A list-of-strings parameter; also accepts one string ("[a, b]", "a b") as rosrun _name:=... gives it.
std::vector<std::string> stringListParam(ros::NodeHandle& pnh, const std::string& name,
                                         const std::vector<std::string>& fallback);
// Planar part of a 3D transform: x, y and the yaw of the x axis.
Eigen::Isometry2d planar(const Eigen::Isometry3d& t);

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
  // One picker with a GNSS device: its ingest (fix checks, bias estimate), its tracker's recent beliefs, its
  // subscriptions and bias topic.
  struct Picker {
    Picker(const core::PickerConfig& config, std::shared_ptr<const topology::TopologicalMap> map,
           const core::GeodeticDatum& datum, const sensors::GnssIngestOptions& options)
        : config(config), ingest(config.id, std::move(map), datum, options) {}
    core::PickerConfig config;
    sensors::GnssIngest ingest;
    sensors::BeliefHistory beliefs;
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
  void addPicker(const core::PickerConfig& p);
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
  std::vector<sensors::GnssIngest*> pickerPointers();
  std::vector<const sensors::BeliefHistory*> beliefHistories() const;
  void releaseOrdered();
  void processFix(Picker& picker, const core::GnssFix& fix);
  void processPerson(const core::Observation& person);
  void publishBias(Picker& picker, double stamp, const sensors::GnssResult& r);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  bool ok_ = false;
  ros::NodeHandle nh_;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::unique_ptr<core::GeodeticDatum> datum_;
  std::string frame_id_, bias_prefix_;
  sensors::GnssIngestOptions options_;
  sensors::IdentityEvidence identity_;  // RFID reads / failed reads per picker (association_identity_sensors)
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
  std::size_t published_ = 0, people_ = 0, identified_ = 0, nobody_ = 0, bad_people_ = 0, registry_updates_ = 0;
  std::size_t picker_poses_ = 0, bad_poses_ = 0;
  std::string people_pose_sensor_ = "people", pose_sensor_ = "pose", pose_topic_format_;
  double people_pose_sigma_ = 0.3;
  std::map<std::string, ros::Subscriber> pose_subs_;  // picker id -> its PoseWithCovarianceStamped topic
  StampGuard stamp_guard_;
  SilenceWatch silence_;
  OnDemandTopics on_demand_;
};

// rfid_ranging: RfidReading -> antenna pose from tf at the read's stamp -> RfidObservationModel.
class RfidRangingNode {
 public:
  RfidRangingNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  bool ok() const { return ok_; }

 private:
  void onReading(const picker_localisation::RfidReading::ConstPtr& msg);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  bool ok_ = false;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::string map_frame_;
  double tf_timeout_ = 0.2;
  std::unique_ptr<sensors::RfidObservationModel> model_;
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::vector<ros::Subscriber> subs_;
  ros::Subscriber registry_sub_;
  ros::Publisher pub_;
  NodeDiagnostics diagnostics_;
  std::size_t tf_failures_ = 0, published_ = 0;
  StampGuard stamp_guard_;
  SilenceWatch silence_;
};

// uwb_ranging: UwbRange (+ optional camera BearingDetectionArray) -> anchors / cameras in base_link and the
// robot pose in the map from tf -> UwbRanging (a Range Histogram Filter per tag).
class UwbRangingNode {
 public:
  UwbRangingNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  bool ok() const { return ok_; }

 private:
  void onRange(const picker_localisation::UwbRange::ConstPtr& msg);
  void onBearings(const picker_localisation::BearingDetectionArray::ConstPtr& msg);
  void onFlush(const ros::WallTimerEvent&);
  void publish(const std::vector<core::Observation>& obs);
  std::string baseFrame(const std::string& robot_id) const;
  // Mount of a sensor frame in base_link (cached: mounts are static).
  std::optional<Eigen::Isometry2d> mount(const std::string& base, const std::string& frame, const ros::Time& stamp,
                                         std::string* error);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  bool ok_ = false;
  std::shared_ptr<const topology::TopologicalMap> map_;
  std::string map_frame_, base_frame_;
  double tf_timeout_ = 0.2;
  std::unique_ptr<sensors::UwbRanging> uwb_;
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::map<std::string, Eigen::Isometry2d> mounts_;
  std::vector<ros::Subscriber> subs_;
  ros::Subscriber registry_sub_;
  ros::Publisher pub_;
  ros::WallTimer flush_timer_;
  NodeDiagnostics diagnostics_;
  std::size_t tf_failures_ = 0, published_ = 0, bearing_sets_ = 0;
  StampGuard stamp_guard_;
  SilenceWatch silence_;
  bool have_range_ = false;
  double newest_stamp_ = 0.0;     // newest accepted-or-not range stamp (s)
  ros::WallTime last_arrival_;    // wall time of the last range message
};

}  // namespace ros_adapter
}  // namespace picker_localisation
