// The rfid_ranging node's ROS adapter (see ranging_nodes.h for what the ranging front-ends share).
#pragma once

#include "picker_localisation/ros/ranging_nodes.h"

namespace picker_localisation {
namespace ros_adapter {

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
  std::unique_ptr<MapFollower> map_follower_;  // a map edited at run time (map topic)
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

}  // namespace ros_adapter
}  // namespace picker_localisation
