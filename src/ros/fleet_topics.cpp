#include "picker_localisation/ros/fleet_topics.h"

#include <picker_localisation/PickerList.h>
#include <ros/names.h>

#include <set>
#include <stdexcept>

#include "picker_localisation/ros/observation_conversions.h"

namespace picker_localisation {
namespace ros_adapter {

ros::Subscriber followPickerList(ros::NodeHandle& nh, ros::NodeHandle& pnh, const char* node,
                                 std::function<void(const core::PickerRegistry&)> apply) {
  std::string topic;
  pnh.param<std::string>("registry_topic", topic, "/pickers/registry");
  if (topic.empty()) return ros::Subscriber();
  const std::string name = node;
  return nh.subscribe<picker_localisation::PickerList>(
      topic, 2, [name, apply](const picker_localisation::PickerList::ConstPtr& msg) {
        std::vector<core::PickerConfig> pickers;
        std::string problem;
        for (const auto& info : msg->pickers) {
          pickers.push_back(fromMsg(info));
          std::string error;
          if (!info.gnss_topic.empty() && !ros::names::validate(info.gnss_topic, error))
            problem = "picker '" + info.id + "': gnss_topic: " + error;
        }
        try {
          if (!problem.empty()) throw std::runtime_error(problem);
          apply(core::PickerRegistry(std::move(pickers), "picker list"));
        } catch (const std::exception& e) {
          ROS_WARN("%s: picker list ignored (the previous one stays): %s", name.c_str(), e.what());
        }
      });
}

FleetBeliefs::FleetBeliefs(ros::NodeHandle& nh, ros::NodeHandle& pnh, Callback on_belief)
    : nh_(nh), on_belief_(std::move(on_belief)) {
  pnh.param<std::string>("belief_topic", topic_, "/pickers/beliefs");
  if (topic_.empty()) return;
  fleet_ = nh_.subscribe<picker_localisation::PickerBeliefArray>(
      topic_, 100, [this](const picker_localisation::PickerBeliefArray::ConstPtr& m) {
        for (const auto& b : m->beliefs) on_belief_(b);
      });
}

void followIds(std::map<std::string, ros::Subscriber>& subscriptions, const std::vector<std::string>& ids,
               const std::function<ros::Subscriber(const std::string& id)>& subscribe) {
  const std::set<std::string> wanted(ids.begin(), ids.end());
  for (auto it = subscriptions.begin(); it != subscriptions.end();)
    it = wanted.count(it->first) ? std::next(it) : subscriptions.erase(it);
  for (const std::string& id : wanted)
    if (!subscriptions.count(id)) subscriptions[id] = subscribe(id);
}

void FleetBeliefs::follow(const std::vector<std::string>& ids) {
  if (!perPicker()) return;
  followIds(per_picker_, ids, [this](const std::string& id) {
    return nh_.subscribe<picker_localisation::PickerBelief>(
        "/pickers/" + id + "/belief", 5,
        [this](const picker_localisation::PickerBelief::ConstPtr& m) { on_belief_(*m); });
  });
}

}  // namespace ros_adapter
}  // namespace picker_localisation
