// Releases items in time-stamp order once the clock has passed their stamp by a latency, so that a node's
// processing order depends only on the messages' stamps and contents, never on which publisher's message
// happened to arrive first. This is what makes a replayed bag give the same beliefs twice. ROS-free.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace picker_localisation {
namespace core {

template <class T>
class StampOrderedBuffer {
 public:
  // latency: s an item waits after its stamp before it is released (>= the worst delivery delay expected).
  // max_items: older items are released early when more are held (bounded memory; ordering may then
  // degrade, counted in forcedReleases()).
  explicit StampOrderedBuffer(double latency = 0.5, std::size_t max_items = 10000)
      : latency_(latency), max_items_(max_items) {}

  // `key` breaks ties between equal stamps (e.g. sensor + robot + picker + content digest); items with equal
  // stamp and key keep arrival order.
  void push(double stamp, const std::string& key, T item) {
    items_.emplace(std::make_tuple(stamp, key, counter_++), std::move(item));
  }

  // Items with stamp <= now - latency, ascending (stamp, key); removed from the buffer.
  std::vector<std::pair<double, T>> release(double now) {
    std::vector<std::pair<double, T>> out;
    while (!items_.empty() &&
           (std::get<0>(items_.begin()->first) <= now - latency_ || items_.size() > max_items_)) {
      if (std::get<0>(items_.begin()->first) > now - latency_) ++forced_;
      out.emplace_back(std::get<0>(items_.begin()->first), std::move(items_.begin()->second));
      items_.erase(items_.begin());
    }
    return out;
  }

  // Everything still held, in order (at shutdown or end of a bag).
  std::vector<std::pair<double, T>> releaseAll() { return release(std::numeric_limits<double>::infinity()); }

  std::size_t size() const { return items_.size(); }
  double latency() const { return latency_; }
  std::size_t forcedReleases() const { return forced_; }
  void clear() { items_.clear(); }

 private:
  double latency_;
  std::size_t max_items_;
  std::size_t counter_ = 0;
  std::size_t forced_ = 0;
  std::map<std::tuple<double, std::string, std::size_t>, T> items_;
};

}  // namespace core
}  // namespace picker_localisation
