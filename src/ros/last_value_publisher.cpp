#include "picker_localisation/ros/last_value_publisher.h"

#include <ros/master.h>

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

}  // namespace ros_adapter
}  // namespace picker_localisation
