// Call-aware idle positioning: when each picker's trays were last emptied, and the weight the Next-Best-Sense
// planner gives the picker for it. A picker whose trays are nearly full is about to call, and its call is
// answered on the belief the robots leave it with: an idle robot that looks at it now saves a wrong lane
// later. The runner (from CallDispatcher's calls) and the nbs_planner node (from the dispatcher's ~status)
// feed one TrayClock each, so both weigh the pickers by the same rule. ROS-free.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "picker_localisation/nbs/belief_source.h"

namespace picker_localisation {
namespace nbs {

// Multiplies a picker's w_k in the planner's RFID gain (missing pickers: 1).
using PickerWeights = std::map<std::string, double>;

class TrayClock {
 public:
  // call_due_weight >= 0 (0: every weight 1), tray_time_mean > 0 s (PlannerConfig's keys).
  TrayClock(double call_due_weight, double tray_time_mean);

  // A call of the picker as the dispatcher reports it: made at `called`; `arrived` the stamp its robot sensed
  // the picker (NaN: not yet, or never); `open` whether it is still open. Calls may be reported again and in
  // any order: the trays were emptied at the latest arrival, and the picker waits when its latest call (by
  // `called`) is open and not reached.
  void observeCall(const std::string& picker_id, double called, double arrived, bool open);
  // Forgets every call and the start (the clock jumped back).
  void reset();

  // The planner's weight of the picker at `now`:
  //   1 + call_due_weight * min(1, (now - emptied) / tray_time_mean),
  // emptied = the latest arrival of a robot at the picker (it took the trays), else the first `now` this
  // clock was asked about (the shift's start as far as it knows); a picker waiting for a robot weighs
  // 1 + call_due_weight (a call cancelled before any robot came leaves the trays as they were). Call-due
  // weight 0: 1 for every picker.
  double weight(const std::string& picker_id, double now);
  // weight() of each picker the planner is given (the runner and the node alike).
  PickerWeights weights(const std::vector<BeliefSource*>& pickers, double now);

  double callDueWeight() const { return call_due_weight_; }

 private:
  struct Trays {
    double emptied = std::numeric_limits<double>::quiet_NaN();  // the latest arrival
    double latest_call = -std::numeric_limits<double>::infinity();
    bool waiting = false;  // the latest call is open and no robot has reached the picker
  };
  double call_due_weight_;
  double tray_time_mean_;
  double start_ = std::numeric_limits<double>::quiet_NaN();
  std::map<std::string, Trays> trays_;
};

}  // namespace nbs
}  // namespace picker_localisation
