#include "picker_localisation/ros/last_value_publisher.h"

#include <ros/master.h>

#include <algorithm>
#include <chrono>

namespace picker_localisation {
namespace ros_adapter {

TopicDemand::TopicDemand(double period) : period_(period) { thread_ = std::thread([this] { run(); }); }

TopicDemand::~TopicDemand() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

bool TopicDemand::wanted(const std::string& topic) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return subscribed_.count(topic) > 0;
}

void TopicDemand::run() {
  while (!stop_ && ros::ok()) {
    XmlRpc::XmlRpcValue args, result, payload;
    args[0] = ros::this_node::getName();
    // getSystemState -> [publishers, subscribers, services], each a list of [name, [nodes]].
    if (ros::master::execute("getSystemState", args, result, payload, false) && payload.getType() == XmlRpc::XmlRpcValue::TypeArray &&
        payload.size() >= 2 && payload[1].getType() == XmlRpc::XmlRpcValue::TypeArray) {
      std::unordered_set<std::string> subscribed;
      XmlRpc::XmlRpcValue& subs = payload[1];
      for (int i = 0; i < subs.size(); ++i)
        if (subs[i].getType() == XmlRpc::XmlRpcValue::TypeArray && subs[i].size() >= 2 &&
            subs[i][0].getType() == XmlRpc::XmlRpcValue::TypeString &&
            subs[i][1].getType() == XmlRpc::XmlRpcValue::TypeArray && subs[i][1].size() > 0)
          subscribed.insert(static_cast<std::string>(subs[i][0]));
      {
        std::lock_guard<std::mutex> lock(mutex_);
        subscribed_.swap(subscribed);
      }
      ++polls_;
    }
    for (double waited = 0.0; waited < period_ && !stop_; waited += 0.05)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

void OnDemandTopics::start(ros::NodeHandle& nh, const core::FleetTopicOptions& fleet, std::size_t expected,
                           std::function<std::size_t()> pickers, std::function<void()> sweep) {
  above_ = static_cast<std::size_t>(std::max(0, fleet.on_demand_topics_above));
  period_ = std::max(0.2, fleet.demand_poll_period);
  pickers_ = std::move(pickers);
  sweep_ = std::move(sweep);
  if (expected > above_) demand_ = std::make_unique<TopicDemand>(period_);
  timer_ = nh.createWallTimer(ros::WallDuration(std::max(0.1, period_ / 2.0)), [this](const ros::WallTimerEvent&) { tick(); });
}

void OnDemandTopics::tick() {
  if (onDemand() && !demand_) demand_ = std::make_unique<TopicDemand>(period_);
  const std::uint64_t polls = demand_ ? demand_->polls() : 0;
  if (polls == last_poll_ && (polls > 0 || demand_)) return;  // nothing new from the master
  last_poll_ = polls;
  sweep_();
}

}  // namespace ros_adapter
}  // namespace picker_localisation
