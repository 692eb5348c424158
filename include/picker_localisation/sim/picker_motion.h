// A simulated fruit picker walking a closed tour on the topological map (Navigate-and-Seek Sec. VI, Table I).
// ROS-free.
//
// Motion model (choices where the paper is vague):
//  - The picker walks its tour (lane_layout.h: serpentine over the lanes) forward, interpolating its position
//    linearly along each edge between consecutive tour nodes; heading = direction of travel.
//  - Walking speed: drawn per picker from a normal N(speed_mean, speed_std^2) truncated to
//    [speed_min, speed_max] (rejection sampling) when the picker is created, and drawn again each time it
//    enters a new lane (pickers keep a pace inside a lane, change it between lanes).
//  - Optional dwell (picking): on arriving at a lane node the picker stops for Exp(mean dwell_mean) s
//    (dwell_mean = 0 disables it; the default), and with long_stop_probability for Exp(long_stop_mean) s.
//  - Reversal ("at any step, p_change chance of changing direction for t_reverse seconds"): a "step" is a
//    reversal decision taken every `reverse_step` seconds of forward walking (default 60 s = t_reverse). At
//    each decision the picker turns round with probability p_reverse, walks its tour backwards for t_reverse
//    seconds (it keeps following the graph, through the headland if it gets there), then turns forward again;
//    no decision is taken while a reversal runs. reverse_step = 0 takes the decision at every node arrival
//    instead. Why not every node arrival by default: with 3 m edges at 0.5 m/s a decision per arrival gives a
//    reversal every ~60 s of walking, each undoing ~30 m, i.e. no net progress along the lanes at all; one
//    decision per t_reverse keeps the pickers reversed ~9 % of the time and moving through the lanes.
#pragma once

#include "picker_localisation/sim/lane_layout.h"
#include "picker_localisation/sim/sim_types.h"
#include "picker_localisation/topology/topological_map.h"

#include <random>
#include <string>
#include <vector>

namespace picker_localisation {
namespace sim {

struct PickerMotionParams {
  double speed_mean = 0.5;       // m/s, mean walking speed while picking along a lane
  double speed_std = 0.1;        // m/s
  double speed_min = 0.2;        // m/s, truncation of the speed distribution
  double speed_max = 1.0;        // m/s
  double p_reverse = 0.1;        // probability of turning round at each reversal decision (Table I p_reverse)
  double reverse_step = 60.0;    // s of forward walking between reversal decisions (0: at every node arrival)
  double t_reverse = 60.0;       // s walked backwards after turning round (Table I t_reverse)
  double dwell_mean = 0.0;       // s, mean of the exponential stop at each lane node (0: no stops)
  // Long stops (a picker packing trays, talking, on a break): at each lane node, with this probability, a
  // stop of Exp(mean long_stop_mean) s. 0: none.
  double long_stop_probability = 0.0;
  double long_stop_mean = 180.0;  // s
  // Which lanes the tour walks, in which order (lane_layout.h).
  LaneOrder lane_order = LaneOrder::kSerpentine;
  double leg_radius = 0.06;      // m, leg circle radius (for the laser ray cast)
  double leg_spread = 0.2;       // m between the two legs' centres, across the heading
  double stride_length = 0.6;    // m travelled per full gait cycle (two steps)
  double step_amplitude = 0.15;  // m, max along-heading offset of a leg from the body centre while walking
};

struct PickerState {
  Pose2D pose;                                        // ground truth, map frame
  double speed = 0.0;                                 // m/s, current walking speed (0 while dwelling)
  topology::NodeIndex from = topology::kInvalidNode;  // edge being walked (from -> to, in walking direction)
  topology::NodeIndex to = topology::kInvalidNode;
  double edge_fraction = 0.0;  // [0, 1] along from -> to
  bool reversed = false;       // walking the tour backwards
  double reverse_until = 0.0;  // s, end of the current reversal
  bool dwelling = false;
  double gait_phase = 0.0;                                    // rad
  topology::NodeIndex nearest_node = topology::kInvalidNode;  // node nearest the true position
};

class SimulatedPicker {
 public:
  // `tour` as from buildLaneTour (>= 2 nodes, consecutive nodes adjacent; closed). `rng_seed` seeds this
  // picker's own generator. The picker starts at tour[0] facing tour[1] at time `start_time`.
  SimulatedPicker(const topology::TopologicalMap& map, std::vector<topology::NodeIndex> tour,
                  const PickerMotionParams& params, std::uint64_t rng_seed, double start_time = 0.0);

  // Advances the walk by dt >= 0 seconds to time() + dt.
  void step(double dt);
  double time() const { return time_; }
  const PickerState& state() const { return state_; }
  const Pose2D& pose() const { return state_.pose; }
  // Centres of the two legs in the map frame (gait: the legs swing in antiphase along the heading, amplitude
  // step_amplitude scaled by speed / speed_mean, capped at 1; lateral separation leg_spread).
  std::array<Eigen::Vector2d, 2> legCentres() const;
  double legRadius() const { return params_.leg_radius; }
  const std::vector<topology::NodeIndex>& tour() const { return tour_; }
  // Counters for tests: node arrivals while walking forward, reversal decisions taken, reversals started.
  std::size_t forwardArrivals() const { return forward_arrivals_; }
  std::size_t reversalDecisions() const { return reversal_decisions_; }
  std::size_t reversalsStarted() const { return reversals_started_; }
  std::size_t lanesEntered() const { return lanes_entered_; }

 private:
  void arrive();
  void decideReversal();
  void updatePose();
  double drawSpeed();

  const topology::TopologicalMap* map_;
  std::vector<topology::NodeIndex> tour_;
  PickerMotionParams params_;
  std::mt19937_64 rng_;
  double time_ = 0.0;
  std::size_t tour_pos_ =
      0;  // index in tour_ of state_.from when walking forward, of state_.to when reversed
  double dwell_until_ = 0.0;
  double lane_speed_ = 0.5;
  PickerState state_;
  double next_decision_ = 0.0;  // s, time of the next reversal decision (reverse_step > 0)
  std::size_t forward_arrivals_ = 0, reversal_decisions_ = 0, reversals_started_ = 0, lanes_entered_ = 0;
};

}  // namespace sim
}  // namespace picker_localisation
