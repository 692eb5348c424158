#include "picker_localisation/sim/picker_motion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace picker_localisation {
namespace sim {

using topology::NodeIndex;

SimulatedPicker::SimulatedPicker(const topology::TopologicalMap& map, std::vector<NodeIndex> tour,
                                 const PickerMotionParams& params, std::uint64_t rng_seed, double start_time)
    : map_(&map), tour_(std::move(tour)), params_(params), rng_(rng_seed), time_(start_time) {
  if (tour_.size() < 2) throw std::invalid_argument("SimulatedPicker: the tour needs at least two nodes");
  for (NodeIndex n : tour_)
    if (n >= map.numNodes()) throw std::invalid_argument("SimulatedPicker: tour node out of range");
  if (!(params_.speed_min > 0.0) || params_.speed_max < params_.speed_min)
    throw std::invalid_argument("SimulatedPicker: need 0 < speed_min <= speed_max");
  if (params_.reverse_step < 0.0) throw std::invalid_argument("SimulatedPicker: reverse_step must be >= 0");
  next_decision_ = time_ + params_.reverse_step;
  lane_speed_ = drawSpeed();
  state_.from = tour_[0];
  state_.to = tour_[1];
  state_.speed = lane_speed_;
  if (map_->lane(tour_[0]) != topology::kNoLane) lanes_entered_ = 1;
  updatePose();
}

double SimulatedPicker::drawSpeed() {
  // Truncated normal by rejection; a degenerate distribution falls back to the clamped mean.
  std::normal_distribution<double> n(params_.speed_mean, std::max(params_.speed_std, 0.0));
  for (int i = 0; i < 100; ++i) {
    const double v = params_.speed_std > 0.0 ? n(rng_) : params_.speed_mean;
    if (v >= params_.speed_min && v <= params_.speed_max) return v;
  }
  return std::clamp(params_.speed_mean, params_.speed_min, params_.speed_max);
}

void SimulatedPicker::step(double dt) {
  if (!(dt >= 0.0)) throw std::invalid_argument("SimulatedPicker::step: dt must be >= 0");
  double remaining = dt;
  const std::size_t N = tour_.size();
  int guard = 0;
  while (remaining > 1e-12 && ++guard < 100000) {
    if (state_.dwelling) {
      const double wait = dwell_until_ - time_;
      if (wait > remaining) {
        time_ += remaining;
        remaining = 0.0;
        break;
      }
      time_ = dwell_until_;
      remaining -= wait;
      state_.dwelling = false;
      state_.speed = lane_speed_;
    }
    if (state_.reversed && time_ >= state_.reverse_until - 1e-12) {
      // The reversal is over: turn round where the picker is; the next decision comes reverse_step later.
      state_.reversed = false;
      tour_pos_ = (tour_pos_ + N - 1) % N;
      std::swap(state_.from, state_.to);
      state_.edge_fraction = 1.0 - state_.edge_fraction;
      next_decision_ = time_ + params_.reverse_step;
    }
    const bool timed = params_.reverse_step > 0.0;
    if (timed && !state_.reversed && time_ >= next_decision_ - 1e-12) {
      decideReversal();
      next_decision_ = time_ + params_.reverse_step;
      continue;
    }
    const double len = map_->distance(state_.from, state_.to);
    const double speed = lane_speed_;
    const double to_node = len > 1e-9 ? (1.0 - state_.edge_fraction) * len / speed : 0.0;
    double move = std::min(remaining, to_node);
    bool interrupted = false;  // stopped before the node by the end of a reversal or a decision time
    const double until = state_.reversed ? state_.reverse_until : (timed ? next_decision_ : 1e300);
    if (until - time_ < move) {
      move = std::max(0.0, until - time_);
      interrupted = true;
    }
    if (len > 1e-9) state_.edge_fraction = std::min(1.0, state_.edge_fraction + move * speed / len);
    state_.gait_phase =
        std::fmod(state_.gait_phase + 2.0 * M_PI * speed * move / params_.stride_length, 2.0 * M_PI);
    time_ += move;
    remaining -= move;
    if (!interrupted && move >= to_node - 1e-12) arrive();
  }
  updatePose();
}

void SimulatedPicker::arrive() {
  const std::size_t N = tour_.size();
  const NodeIndex prev = state_.from;
  const NodeIndex node = state_.to;
  if (!state_.reversed) {
    tour_pos_ = (tour_pos_ + 1) % N;
    ++forward_arrivals_;
  } else {
    tour_pos_ = (tour_pos_ + N - 1) % N;
  }
  const auto lane = map_->lane(node);
  if (lane != topology::kNoLane && lane != map_->lane(prev)) {
    ++lanes_entered_;
    lane_speed_ = drawSpeed();
  }
  state_.from = node;
  state_.to = state_.reversed ? tour_[(tour_pos_ + N - 1) % N] : tour_[(tour_pos_ + 1) % N];
  state_.edge_fraction = 0.0;
  state_.speed = lane_speed_;
  if (params_.reverse_step <= 0.0) decideReversal();  // per-arrival decisions
  if (params_.dwell_mean > 0.0 && lane != topology::kNoLane) {
    std::exponential_distribution<double> d(1.0 / params_.dwell_mean);
    state_.dwelling = true;
    state_.speed = 0.0;
    dwell_until_ = time_ + d(rng_);
  }
  if (params_.long_stop_probability > 0.0 && lane != topology::kNoLane &&
      std::bernoulli_distribution(std::min(params_.long_stop_probability, 1.0))(rng_)) {
    std::exponential_distribution<double> d(1.0 / params_.long_stop_mean);
    state_.dwelling = true;
    state_.speed = 0.0;
    dwell_until_ = std::max(dwell_until_, time_) + d(rng_);
  }
}

void SimulatedPicker::decideReversal() {
  if (state_.reversed) return;
  ++reversal_decisions_;
  std::bernoulli_distribution turn(std::clamp(params_.p_reverse, 0.0, 1.0));
  if (!turn(rng_)) return;
  // Turn round where the picker is (on a node or mid-edge).
  state_.reversed = true;
  state_.reverse_until = time_ + params_.t_reverse;
  ++reversals_started_;
  tour_pos_ = (tour_pos_ + 1) % tour_.size();
  std::swap(state_.from, state_.to);
  state_.edge_fraction = 1.0 - state_.edge_fraction;
}

void SimulatedPicker::updatePose() {
  const Eigen::Vector2d a = map_->position2d(state_.from), b = map_->position2d(state_.to);
  const Eigen::Vector2d p = a + state_.edge_fraction * (b - a);
  state_.pose.x = p.x();
  state_.pose.y = p.y();
  if ((b - a).norm() > 1e-9) state_.pose.yaw = std::atan2(b.y() - a.y(), b.x() - a.x());
  state_.nearest_node = map_->nearestNode(p);
}

std::array<Eigen::Vector2d, 2> SimulatedPicker::legCentres() const {
  const Eigen::Vector2d c = state_.pose.position();
  const Eigen::Vector2d h(std::cos(state_.pose.yaw), std::sin(state_.pose.yaw));
  const Eigen::Vector2d n(-h.y(), h.x());
  const double scale = params_.speed_mean > 0.0 ? std::min(1.0, state_.speed / params_.speed_mean) : 0.0;
  const double swing = params_.step_amplitude * scale * std::sin(state_.gait_phase);
  return {c + swing * h + 0.5 * params_.leg_spread * n, c - swing * h - 0.5 * params_.leg_spread * n};
}

}  // namespace sim
}  // namespace picker_localisation
