// What a consumer of many pickers reads from the trackers (tpf_tracker publishes both): the picker list and
// the beliefs. One place, so gnss_ingest, rfid_ranging, uwb_ranging, nbs_planner and the evaluator follow the
// same topics with the same parameters.
#pragma once

#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/PickerBeliefArray.h>
#include <ros/ros.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "picker_localisation/core/node_options.h"
#include "picker_localisation/core/picker_registry.h"

namespace picker_localisation {
namespace ros_adapter {

// "" when `topic` can be a picker's GNSS topic for every node ("" = none), else why not: a valid ROS name,
// not a private (~) one. The tracker refuses such a picker, the followers such a list.
std::string gnssTopicProblem(const std::string& topic);

// Follows tpf_tracker's picker list (fleet.registry_topic, default /pickers/registry; "" = never): each valid
// list is handed to `apply`; an invalid one (bad id, duplicate, a tag or GNSS topic on two pickers, a bad
// GNSS topic name) is ignored with one warning naming `node` and the reason, the previous list stays. Only
// lists published by the node fleet.registry_publisher (default /tpf_tracker; "" any node) are followed: a
// list from another node is ignored with a throttled warning naming it.
ros::Subscriber followPickerList(ros::NodeHandle& nh, const core::FleetTopicOptions& fleet, const char* node,
                                 std::function<void(const core::PickerRegistry&)> apply);

// Keeps one subscription per picker id: drops those of ids not in `ids`, makes the missing ones with
// `subscribe(id)`. For per-picker input topics that follow the tracker's list.
void followIds(std::map<std::string, ros::Subscriber>& subscriptions, const std::vector<std::string>& ids,
               const std::function<ros::Subscriber(const std::string& id)>& subscribe);

// The trackers' beliefs. `topic` (a node's belief_topic, default /pickers/beliefs) is tpf_tracker's fleet
// stream (PickerBeliefArray): one connection whatever the number of pickers. "" reads each picker's
// own latched /pickers/<id>/belief instead (trackers of another package, or a consumer started long after a
// belief that does not change). Every belief reaches `on_belief`, whichever picker it names: the consumer
// looks the id up.
class FleetBeliefs {
 public:
  using Callback = std::function<void(const picker_localisation::PickerBelief&)>;
  FleetBeliefs(ros::NodeHandle& nh, const std::string& topic, Callback on_belief);
  FleetBeliefs(const FleetBeliefs&) = delete;  // the subscriptions call back into this object
  FleetBeliefs& operator=(const FleetBeliefs&) = delete;
  // The pickers to read: with per-picker topics, subscribes the new ones and drops the others; with the fleet
  // stream nothing changes.
  void follow(const std::vector<std::string>& ids);
  bool perPicker() const { return topic_.empty(); }
  // The topic read ("/pickers/<id>/belief" with per-picker topics).
  std::string topic() const { return perPicker() ? "/pickers/<id>/belief" : topic_; }

 private:
  ros::NodeHandle nh_;
  std::string topic_;
  Callback on_belief_;
  ros::Subscriber fleet_;
  std::map<std::string, ros::Subscriber> per_picker_;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
