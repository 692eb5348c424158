#include "picker_localisation/tpf/tracker_fleet.h"

#include <cmath>
#include <stdexcept>

namespace picker_localisation {
namespace tpf {

TrackerFleet::TrackerFleet(std::shared_ptr<const topology::TopologicalMap> map, BeliefListener listener)
    : map_(std::move(map)), listener_(std::move(listener)) {
  if (!map_) throw std::invalid_argument("TrackerFleet: null map");
}

std::uint64_t TrackerFleet::seedFor(const std::string& id, std::uint64_t base) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : id) h = (h ^ c) * 1099511628211ull;
  for (int k = 0; k < 8 && base != 0; ++k, base >>= 8) h = (h ^ (base & 0xff)) * 1099511628211ull;
  return h == 0 ? 1 : h;
}

TrackerFleet::Track* TrackerFleet::add(const std::string& id, const TpfParams& params, std::uint64_t seed,
                                       std::string* error) {
  auto fail = [error](const std::string& why) -> Track* {
    if (error) *error = why;
    return nullptr;
  };
  if (tracks_.count(id)) return fail("picker '" + id + "' is tracked already");
  auto t = std::make_unique<Track>();
  t->id = id;
  t->seed = seed;
  try {
    t->filter = std::make_unique<TopologicalParticleFilter>(map_, params, seed);
  } catch (const std::exception& e) {  // invalid parameters or std::bad_alloc: this picker only
    return fail(std::string("its filter could not be made: ") + e.what());
  }
  t->prediction_period = params.prediction_rate > 0.0 ? 1.0 / params.prediction_rate : 0.0;
  Track* raw = t.get();
  tracks_[id] = std::move(t);
  return raw;
}

bool TrackerFleet::remove(const std::string& id) {
  return tracks_.erase(id) > 0;
}

TrackerFleet::Track* TrackerFleet::find(const std::string& id) {
  const auto it = tracks_.find(id);
  return it == tracks_.end() ? nullptr : it->second.get();
}

std::vector<TrackerFleet::Track*> TrackerFleet::route(bool identifying, const std::string& picker_id,
                                                      const std::vector<std::string>& candidates) {
  std::vector<Track*> out;
  if (identifying || !candidates.empty()) {
    for (const std::string& id : identifying ? std::vector<std::string>{picker_id} : candidates)
      if (Track* t = find(id)) out.push_back(t);
    return out;
  }
  out.reserve(tracks_.size());
  for (auto& kv : tracks_) out.push_back(kv.second.get());
  return out;
}

std::vector<TrackerFleet::Outcome> TrackerFleet::process(const core::Observation& obs) {
  std::vector<Outcome> out;
  for (Track* t : route(obs.identifying, obs.picker_id, obs.candidate_pickers))
    out.push_back(process(*t, obs));
  return out;
}

TrackerFleet::Outcome TrackerFleet::process(Track& t, const core::Observation& obs) {
  Outcome out;
  out.track = &t;
  ++t.received;
  try {
    if (std::isfinite(obs.stamp)) predictDue(t, obs.stamp);
    out.result = t.filter->update(obs, core::associationProbability(obs, t.id));
  } catch (const std::exception& e) {
    caught(t, e);
    out.exception = true;
    out.result.status = UpdateStatus::kRejectedInvalid;
    out.result.reason = t.last_problem;
    return out;
  }
  if (!out.result.ok()) {
    if (out.result.status != UpdateStatus::kIgnoredSensor)
      t.last_problem = std::string(toString(out.result.status)) + ": " + out.result.reason;
    return out;
  }
  changed(t);
  return out;
}

void TrackerFleet::predictDue(Track& t, double until) {
  if (t.prediction_period <= 0.0) return;
  TopologicalParticleFilter& f = *t.filter;
  int steps = 0;
  while (f.initialised() && until - f.lastStamp() >= t.prediction_period) {
    const double next = ++steps < kMaxPredictionsPerCall ? f.lastStamp() + t.prediction_period
                                                         : until;  // a long silence: one step to `until`
    if (!f.predictTo(next)) break;
    changed(t);
  }
}

void TrackerFleet::predictDue(double until) {
  for (auto& kv : tracks_) {
    try {
      predictDue(*kv.second, until);
    } catch (const std::exception& e) {
      caught(*kv.second, e);
    }
  }
}

void TrackerFleet::reset(Track& t) {
  t.filter->reset();
  ++t.resets;
  changed(t);
}

void TrackerFleet::resetAll() {
  for (auto& kv : tracks_) reset(*kv.second);
}

void TrackerFleet::caught(Track& t, const std::exception& e) {
  ++t.exceptions;
  t.last_problem = std::string("exception: ") + e.what();
  try {
    t.filter->reset();
  } catch (const std::exception&) {
  }
  changed(t);
}

std::vector<std::string> TrackerFleet::adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                                                const std::vector<topology::NodeIndex>& old_to_new) {
  if (!map) throw std::invalid_argument("TrackerFleet::adoptMap: null map");
  map_ = std::move(map);
  std::vector<std::string> afresh;
  for (auto& kv : tracks_) {
    Track& t = *kv.second;
    try {
      t.filter->adoptMap(map_, old_to_new);
    } catch (const std::exception& e) {
      // The filter is still on the old map (adoptMap changes nothing when it throws): a fresh one on the new
      // map, its belief forgotten, so every filter shares one map.
      ++t.exceptions;
      t.last_problem = std::string("belief not carried to the new map: ") + e.what();
      t.filter = std::make_unique<TopologicalParticleFilter>(map_, t.filter->params(), t.seed);
      afresh.push_back(t.id);
    }
    changed(t);
  }
  return afresh;
}

double TrackerFleet::fastestPredictionPeriod() const {
  double fastest = 0.0;
  for (const auto& kv : tracks_)
    if (kv.second->prediction_period > 0.0 && (fastest == 0.0 || kv.second->prediction_period < fastest))
      fastest = kv.second->prediction_period;
  return fastest;
}

}  // namespace tpf
}  // namespace picker_localisation
