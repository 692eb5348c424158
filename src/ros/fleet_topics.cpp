#include "picker_localisation/ros/fleet_topics.h"

#include <picker_localisation/PickerList.h>
#include <ros/names.h>

#include <set>
#include <stdexcept>

#include "picker_localisation/ros/observation_conversions.h"

namespace picker_localisation {
namespace ros_adapter {

std::string gnssTopicProblem(const std::string& topic) {
  if (topic.empty()) return "";
  // A private name means a different topic in every node that resolves it (the tracker's ~fix is not
  // gnss_ingest's), and roscpp refuses it on a public NodeHandle.
  if (topic[0] == '~')
    return "gnss_topic '" + core::clippedForLog(topic) +
           "': a private (~) name; give a global or relative name";
  std::string error;
  if (!ros::names::validate(topic, error)) return "gnss_topic: " + core::clippedForLog(error);
  return "";
}

ros::Subscriber followPickerList(ros::NodeHandle& nh, const core::FleetTopicOptions& fleet, const char* node,
                                 std::function<void(const core::PickerRegistry&)> apply) {
  const std::string topic = fleet.registry_topic;
  if (topic.empty()) return ros::Subscriber();
  // Only the tracker's list: any node may publish on the topic, and one empty list from a stranger would drop
  // every picker's GNSS subscription.
  std::string publisher = fleet.registry_publisher;
  if (!publisher.empty()) publisher = ros::names::resolve(publisher);
  const std::string name = node;
  // One warning per foreign publisher (at most 100 named): each stranger is named once, none floods the log.
  auto warned = std::make_shared<std::set<std::string>>();
  return nh.subscribe<picker_localisation::PickerList>(
      topic, 2,
      boost::function<void(const ros::MessageEvent<picker_localisation::PickerList const>&)>(
          [name, publisher, apply, warned](const ros::MessageEvent<picker_localisation::PickerList const>& event) {
            if (!publisher.empty() && event.getPublisherName() != publisher) {
              if (warned->size() < 100 && warned->insert(event.getPublisherName()).second)
                ROS_WARN("%s: picker list from %s ignored: only %s's lists are followed (~registry_publisher)",
                         name.c_str(), core::clippedForLog(event.getPublisherName()).c_str(), publisher.c_str());
              return;
            }
            const picker_localisation::PickerList& msg = *event.getConstMessage();
            std::vector<core::PickerConfig> pickers;
            std::string problem;
            for (const auto& info : msg.pickers) {
              pickers.push_back(fromMsg(info));
              const std::string topic_problem = gnssTopicProblem(info.gnss_topic);
              if (!topic_problem.empty())
                problem = "picker '" + core::clippedForLog(info.id) + "': " + topic_problem;
            }
            try {
              if (!problem.empty()) throw std::runtime_error(problem);
              apply(core::PickerRegistry(std::move(pickers), "picker list"));
            } catch (const std::exception& e) {
              ROS_WARN("%s: picker list ignored (the previous one stays): %s", name.c_str(), e.what());
            }
          }));
}

FleetBeliefs::FleetBeliefs(ros::NodeHandle& nh, const std::string& topic, Callback on_belief)
    : nh_(nh), topic_(topic), on_belief_(std::move(on_belief)) {
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
