// Publishers that cost nothing while nobody listens. In roscpp every
// publish to a latched topic serialises the message and wakes the poll thread, which then walks every
// publication of the process; ros::Publisher::getNumSubscribers() finds its topic by a linear scan of them;
// every socket write rebuilds the poll set. With thousands of per-picker topics in one node that, not the
// filters, was the cost (measured with perf and bench_fleet).
//  * CountedPublisher: the subscriber count kept from connect / disconnect callbacks; an optional
//  `on_connect`
//    sends a new subscriber something at once.
//  * LastValuePublisher: latched semantics (a new subscriber gets the last message at once), a message sent
//    only when the topic has subscribers; it may be advertised and shut down again (TopicDemand) while it
//    keeps the last message.
//  * TopicDemand: which topics some node subscribes to, from the master (getSystemState), polled by a thread;
//    a node with thousands of per-picker topics advertises them only while someone wants them.
#pragma once

#include <ros/ros.h>

#include "picker_localisation/core/node_options.h"

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_set>

namespace picker_localisation {
namespace ros_adapter {

class CountedPublisher {
 public:
  using OnConnect = std::function<void(const ros::SingleSubscriberPublisher&)>;
  CountedPublisher() = default;
  template <class Message>
  static CountedPublisher advertise(ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue_size,
                                    OnConnect on_connect = {}, bool latch = false) {
    CountedPublisher p;
    p.count_ = std::make_shared<std::uint32_t>(0);
    p.pub_ = nh.advertise<Message>(
        topic, queue_size,
        [count = p.count_, on_connect](const ros::SingleSubscriberPublisher& s) {
          ++*count;
          if (on_connect) on_connect(s);
        },
        [count = p.count_](const ros::SingleSubscriberPublisher&) {
          if (*count > 0) --*count;
        },
        ros::VoidConstPtr(), latch);
    return p;
  }
  bool advertised() const { return count_ != nullptr; }
  bool hasSubscribers() const { return count_ && *count_ > 0; }
  template <class Message>
  void publish(const Message& m) const {
    if (hasSubscribers()) pub_.publish(m);
  }
  void shutdown() {
    pub_.shutdown();
    pub_ = ros::Publisher();
    count_.reset();
  }

 private:
  std::shared_ptr<std::uint32_t> count_;
  ros::Publisher pub_;
};

template <class Message>
class LastValuePublisher {
 public:
  LastValuePublisher() : last_(std::make_shared<std::optional<Message>>()) {}
  void advertise(ros::NodeHandle& nh, const std::string& topic, std::uint32_t queue_size) {
    pub_ = CountedPublisher::advertise<Message>(nh, topic, queue_size,
                                                [last = last_](const ros::SingleSubscriberPublisher& s) {
                                                  if (*last) s.publish(**last);
                                                });
  }
  void shutdown() { pub_.shutdown(); }
  void publish(Message m) {
    pub_.publish(m);
    *last_ = std::move(m);
  }
  bool advertised() const { return pub_.advertised(); }
  bool hasSubscribers() const { return pub_.hasSubscribers(); }

 private:
  std::shared_ptr<std::optional<Message>> last_;
  CountedPublisher pub_;
};

class TopicDemand {
 public:
  // Polls the master every `period` s (wall time: transport only) for the topics with subscribers.
  explicit TopicDemand(double period);
  ~TopicDemand();
  TopicDemand(const TopicDemand&) = delete;
  TopicDemand& operator=(const TopicDemand&) = delete;
  // True when the last poll found a subscriber of `topic` (fully resolved name).
  bool wanted(const std::string& topic) const;
  // Number of polls answered so far (a caller re-checks its topics when it changes).
  std::uint64_t polls() const { return polls_; }

 private:
  void run();
  double period_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> polls_{0};
  mutable std::mutex mutex_;
  std::unordered_set<std::string> subscribed_;
  std::thread thread_;
};

// The on-demand policy of a node with per-picker topics (tpf_tracker, gnss_ingest): parameters
// ~on_demand_topics_above (100) and ~demand_poll_period (2 s). Above that many pickers the master is polled
// (TopicDemand) and `sweep` runs whenever a poll brought news; at or below it, `sweep` runs on every tick, so a
// topic shut down while on demand is advertised again.
class OnDemandTopics {
 public:
  OnDemandTopics() = default;
  // `expected`: the pickers the node starts with (polling starts at once when they are many); `pickers`: how
  // many it has now; `sweep`: re-applies advertiseWhileWanted to every per-picker topic.
  // fleet: on_demand_topics_above, demand_poll_period.
  void start(ros::NodeHandle& nh, const core::FleetTopicOptions& fleet, std::size_t expected,
             std::function<std::size_t()> pickers, std::function<void()> sweep);
  bool onDemand() const { return pickers_ && pickers_() > above_; }
  // What to advertise by: nullptr (always) unless on demand.
  const TopicDemand* demand() const { return onDemand() ? demand_.get() : nullptr; }

 private:
  void tick();
  std::size_t above_ = 100;
  double period_ = 2.0;
  std::function<std::size_t()> pickers_;
  std::function<void()> sweep_;
  std::unique_ptr<TopicDemand> demand_;
  std::uint64_t last_poll_ = 0;
  ros::WallTimer timer_;
};

// Keeps `pub` advertised on `topic` (resolved name) while it is wanted: always when `demand` is null, else while
// the master lists a subscriber or the publisher still has one. `advertise` advertises it.
template <class Publisher, class Advertise>
void advertiseWhileWanted(Publisher& pub, const std::string& topic, const TopicDemand* demand, Advertise&& advertise) {
  const bool wanted = !demand || pub.hasSubscribers() || demand->wanted(topic);
  if (wanted && !pub.advertised()) {
    advertise();
  } else if (!wanted && pub.advertised()) {
    pub.shutdown();
  }
}

}  // namespace ros_adapter
}  // namespace picker_localisation
