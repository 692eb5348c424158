// The Topological Particle Filters of a farm's pickers, one per picker (Navigate-and-Seek Sec. IV), with the
// schedule every user of them shares. ROS-free: the tpf_tracker node drives it from its topics and timers,
// the offline runner from the simulator's events, so both fuse the same observations at the same stamps.
// - Routing: an observation goes to the one picker it identifies, to its candidate pickers, or (anonymous, no
//   candidates) to every picker (core::concernsPicker's rule, by lookup).
// - Prediction schedule: while no observation arrives a picker predicts at lastStamp + k / prediction_rate
//   (Khan et al. Table I: 0.25 Hz; predictDue), and the predictions that fall due before an observation's
//   stamp are made before it is fused, so a belief never depends on when a timer fired. A silence longer than
//   kMaxPredictionsPerCall periods is bridged by one prediction.
// - Containment: an exception out of a filter (std::bad_alloc) resets that picker's belief and is counted;
// the
//   other pickers go on.
// Every belief change (an accepted update, a prediction, a reset) is reported to the listener, in order.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/tpf/topological_particle_filter.h"

namespace picker_localisation {
namespace tpf {

class TrackerFleet {
 public:
  struct Track {
    std::string id;
    std::unique_ptr<TopologicalParticleFilter> filter;
    std::uint64_t seed = 1;          // the filter's seed (a filter started afresh gets it again)
    double prediction_period = 0.0;  // s; 0: no periodic prediction
    std::uint64_t received = 0, resets = 0, exceptions = 0;
    std::string last_problem;  // the last refused observation or exception ("" none), for diagnostics
  };
  // One picker's result of an observation; `exception` when the filter threw (its belief was reset).
  struct Outcome {
    Track* track = nullptr;
    UpdateResult result;
    bool exception = false;
  };
  using BeliefListener = std::function<void(Track&)>;
  static constexpr int kMaxPredictionsPerCall = 100;
  // A picker's filter seed: FNV-1a of its id, mixed with `base` when non-zero; never 0. Stable across runs
  // and processes, different per picker, so the node and the runner seed the same picker alike.
  static std::uint64_t seedFor(const std::string& id, std::uint64_t base = 0);

  explicit TrackerFleet(std::shared_ptr<const topology::TopologicalMap> map, BeliefListener listener = {});

  // Starts tracking `id` with its own parameters and seed; nullptr and *error (nothing changed) when it is
  // tracked already or its filter cannot be made (invalid parameters, std::bad_alloc).
  Track* add(const std::string& id, const TpfParams& params, std::uint64_t seed,
             std::string* error = nullptr);
  bool remove(const std::string& id);
  Track* find(const std::string& id);
  std::size_t size() const { return tracks_.size(); }
  const std::map<std::string, std::unique_ptr<Track>>& tracks() const { return tracks_; }
  const std::shared_ptr<const topology::TopologicalMap>& map() const { return map_; }

  // The pickers an observation concerns.
  std::vector<Track*> route(bool identifying, const std::string& picker_id,
                            const std::vector<std::string>& candidates);
  // Fuses `obs` into every picker it concerns, each after its due predictions: one outcome per picker.
  std::vector<Outcome> process(const core::Observation& obs);
  Outcome process(Track& track, const core::Observation& obs);
  // Every picker's periodic predictions due up to `until` (s).
  void predictDue(double until);
  // Forgets a belief (the next observation initialises it again).
  void reset(Track& track);
  void resetAll();
  // Every filter onto `map` (TopologicalParticleFilter::adoptMap: particles on removed nodes to the nearest
  // node of the new map). A filter that cannot be carried over starts afresh on the new map; their ids are
  // returned. Every belief is reported to the listener.
  std::vector<std::string> adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                                    const std::vector<topology::NodeIndex>& old_to_new);
  // The shortest prediction period of any picker (0 when none predicts periodically).
  double fastestPredictionPeriod() const;

 private:
  void predictDue(Track& track, double until);
  void caught(Track& track, const std::exception& e);
  void changed(Track& track) {
    if (listener_) listener_(track);
  }

  std::shared_ptr<const topology::TopologicalMap> map_;
  BeliefListener listener_;
  std::map<std::string, std::unique_ptr<Track>> tracks_;
};

}  // namespace tpf
}  // namespace picker_localisation
