#include "picker_localisation/nbs/tray_clock.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace picker_localisation {
namespace nbs {

TrayClock::TrayClock(double call_due_weight, double tray_time_mean)
    : call_due_weight_(call_due_weight), tray_time_mean_(tray_time_mean) {
  if (!(call_due_weight >= 0.0) || !std::isfinite(call_due_weight))
    throw std::invalid_argument("TrayClock: call_due_weight must be finite and >= 0");
  if (!(tray_time_mean > 0.0) || !std::isfinite(tray_time_mean))
    throw std::invalid_argument("TrayClock: tray_time_mean must be finite and > 0");
}

void TrayClock::observeCall(const std::string& picker_id, double called, double arrived, bool open) {
  if (picker_id.empty() || !std::isfinite(called)) return;
  Trays& t = trays_[picker_id];
  if (std::isfinite(arrived) && !(arrived <= t.emptied)) t.emptied = arrived;
  if (called >= t.latest_call) {
    t.latest_call = called;
    t.waiting = open && !std::isfinite(arrived);
  }
}

void TrayClock::reset() {
  trays_.clear();
  start_ = std::numeric_limits<double>::quiet_NaN();
}

double TrayClock::weight(const std::string& picker_id, double now) {
  if (std::isnan(start_)) start_ = now;
  if (call_due_weight_ == 0.0) return 1.0;
  double emptied = start_;
  const auto it = trays_.find(picker_id);
  if (it != trays_.end()) {
    if (it->second.waiting) return 1.0 + call_due_weight_;  // calling, no robot there yet: the trays are full
    if (std::isfinite(it->second.emptied)) emptied = it->second.emptied;
  }
  const double filled = std::clamp((now - emptied) / tray_time_mean_, 0.0, 1.0);
  return 1.0 + call_due_weight_ * filled;
}

PickerWeights TrayClock::weights(const std::vector<BeliefSource*>& pickers, double now) {
  PickerWeights out;
  for (const BeliefSource* p : pickers)
    if (p) out[p->pickerId()] = weight(p->pickerId(), now);
  return out;
}

}  // namespace nbs
}  // namespace picker_localisation
