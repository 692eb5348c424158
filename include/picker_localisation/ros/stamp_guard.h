// Time sanity for nodes that keep time state (no input may stop a node): stamps implausibly far in the future
// are rejected instead of adopted (one would block every later message), and a backwards jump of the node's
// clock (a bag replayed with -l, a simulator restart) is detected once so the node can reset its time state.
// Differences are taken in double seconds: ros::Duration throws ("out of dual 32-bit range") for a stamp
// decades away.
#pragma once

#include <ros/time.h>

namespace picker_localisation {
namespace ros_adapter {

// Seconds from `from` to `to` (never throws).
inline double secondsBetween(const ros::Time& from, const ros::Time& to) {
  return to.toSec() - from.toSec();
}

// A node's ~ordering_latency: a value >= 0 as given; a negative one (the default, "automatic") is
// `replay_latency` under /use_sim_time (bags, simulator: messages wait and are processed in stamp order, so a
// replay is deterministic) and 0 live (each message processed on arrival: milliseconds of latency).
inline double orderingLatency(double param, double replay_latency) {
  if (param >= 0.0) return param;
  return ros::Time::isSimTime() ? replay_latency : 0.0;
}

class StampGuard {
 public:
  explicit StampGuard(double max_future = 10.0, double jump_tolerance = 1.0)
      : max_future_(max_future), jump_tolerance_(jump_tolerance) {}
  // True (and counted) when `stamp` lies more than max_future s after the node's clock. Before the clock runs
  // (sim time, no /clock yet: now is 0) the reference is the wall clock: no recorded or simulated stamp can be
  // later than today, and a stamp adopted then would block the node as surely as later.
  bool tooFarInFuture(const ros::Time& stamp) {
    double now = ros::Time::now().toSec();
    if (now <= 0.0) now = ros::WallTime::now().toSec();
    const bool far = max_future_ > 0.0 && stamp.toSec() - now > max_future_;
    if (far) ++future_stamps_;
    return far;
  }
  // True once per backwards jump of the node's clock by more than jump_tolerance s since the last call.
  bool clockJumpedBack() {
    const double now = ros::Time::now().toSec();
    const bool jumped = now + jump_tolerance_ < last_now_;
    last_now_ = now;
    if (jumped) ++jumps_;
    return jumped;
  }
  std::size_t jumps() const { return jumps_; }
  std::size_t futureStamps() const { return future_stamps_; }  // messages tooFarInFuture() refused
  double maxFuture() const { return max_future_; }

 private:
  double max_future_, jump_tolerance_;
  double last_now_ = 0.0;
  std::size_t jumps_ = 0, future_stamps_ = 0;
};

}  // namespace ros_adapter
}  // namespace picker_localisation
