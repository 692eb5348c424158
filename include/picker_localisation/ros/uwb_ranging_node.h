// The uwb_ranging node's ROS adapter (see ranging_nodes.h for what the ranging front-ends share).
#pragma once

#include "picker_localisation/ros/ranging_nodes.h"

namespace picker_localisation {
namespace ros_adapter {

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
  std::unique_ptr<MapFollower> map_follower_;  // a map edited at run time (map topic)
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
