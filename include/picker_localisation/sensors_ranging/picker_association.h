// Identity for anonymous people detections (Khan et al. 2020, Sec. VI: the lane a robot is sent to).
// ROS-free.
//
// A confirmed person from the LiDAR (or camera-fused legs) names nobody. Each picker predicts where it is
// from two sources:
//   g_i(z) = N(z; fix_i - bias_i, P_bias_i + residual^2 I + (speed age)^2 I + R_z)   bias-corrected fix
//   b_i(z) = sum_n m_i(n) N(z; x_n, belief_sigma^2 I + R_z)                           tracker's belief
// and the detection's likelihood under "it is picker i" is the mixture l_i = (1 - w) g_i + w b_i (either term
// alone when the other is missing). A mixture, not a product: the belief was built from the same fixes, and a
// confidently wrong belief must not veto the fix (that is the lane we want to correct). Against the
// hypothesis "nobody we track" (clutter density c: false legs, other workers) the association probabilities
// are p_i = l_i / (c + sum_j l_j) for one detection (the single-scan PDA form); the people of one scan are
// associated jointly, each picker at most one of them (associatePeople).
// p_i >= min_probability makes the detection an identifying observation of picker i and a metric sighting for
// its bias estimate; anything less stays anonymous, for the trackers of the pickers whose p_i reaches
// association_min_candidate_probability (Observation::candidate_pickers; none: not published at all). Before
// the first sighting the bias prior is wide (sqrt(offset_std^2 + drift_std^2) = 3.2 m per axis), so only a
// detection that is both near the fix and far from every other picker is identified; once identified, the
// corrected fix is sharp and the next sightings follow.
#pragma once

#include <deque>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace sensors {

// A tracker's belief as the association reads it (sparse node masses summing to 1).
struct BeliefView {
  const std::vector<topology::NodeIndex>* nodes = nullptr;
  const std::vector<double>* masses = nullptr;
  double stamp = 0.0;
  bool valid() const { return nodes && masses && nodes->size() == masses->size() && !nodes->empty(); }
};

// The beliefs a tracker published, newest last, so the association can use the belief of a fixed lag before
// the detection (association_belief_lag): in the ROS graph a tracker's belief reaches gnss_ingest after its
// own ordering latency, and a belief chosen by stamp, not by arrival, keeps replay deterministic. The runner
// keeps the same history, so both use the same belief.
class BeliefHistory {
 public:
  // Stores a copy when `stamp` is newer than the newest kept (an equal stamp replaces it); keeps `horizon` s,
  // and at most kMaxItems beliefs (the newest): 30 s of beliefs at 30 Hz, bounded whatever a tracker sends.
  static constexpr std::size_t kMaxItems = 1000;
  void push(double stamp, const std::vector<topology::NodeIndex>& nodes, const std::vector<double>& masses,
            double horizon = 30.0);
  // The newest belief with stamp <= t (invalid view when none).
  BeliefView atOrBefore(double t) const;
  void clear() { items_.clear(); }
  std::size_t size() const { return items_.size(); }

 private:
  struct Item {
    double stamp;
    std::vector<topology::NodeIndex> nodes;
    std::vector<double> masses;
  };
  std::deque<Item> items_;
};

// One view per picker: the belief association_belief_lag before `stamp`.
std::vector<BeliefView> beliefViews(const std::vector<BeliefHistory>& histories, double stamp,
                                    const PickerAssociationOptions& options);
std::vector<BeliefView> beliefViews(const std::vector<const BeliefHistory*>& histories, double stamp,
                                    const PickerAssociationOptions& options);

// Identity evidence for the association. An RFID read names its picker but puts it
// only somewhere within ~5 m of the antenna, too coarse (and too correlated from read to read) to measure a
// 1-2 m bias, but decisive about *who* a detection 1 m from the antenna is when the pickers' biased fixes are
// 5 m apart: measured on the three-picker scenario, the true picker's tag had been read within 2 s before
// 644 of 661 wrong identifications. For each picker, the newest identifying observation of every (sensor,
// robot) in identity_sensors is kept (a read, or an antenna's negative observation for a tag it has not read)
// and weighs l_i by
//   rho_i(z) = max(L(z), floor) / max(E_{x ~ N(prediction_i)}[L(x)], floor)
// with L the observation's own likelihood over nodes, read at a position x on the graph point nearest x
// (TopologicalMap::nearestEdgePoint: linear between the two nodes of the edge) and the expectation a 3 x 3
// Gauss-Hermite rule over the picker's predicted position (bias-corrected fix, the g_i term). rho > 1: the
// observation is better explained by the picker standing at the detection than where it is predicted (a read
// next to the detection of a picker whose fix is 9 m away); rho < 1: worse (an antenna 1 m from the detection
// has not read this picker's tag for seconds). Only ratios enter, so evidence consistent with the prediction
// changes nothing, and one observation per sensor and robot (not every read) avoids counting one antenna's
// correlated reads many times.
class IdentityEvidence {
 public:
  // Keeps `obs` when it is identifying, names a picker, comes from a sensor in options.identity_sensors and
  // lists at least one node; replaces the (picker, sensor, robot) entry only with a newer or equal stamp.
  bool add(const core::Observation& obs, const PickerAssociationOptions& options);
  // rho_i(z) for `picker_id` at stamp t (1 when nothing within identity_window), `mean` / `covariance` the
  // picker's predicted position (covariance including the detection's own).
  double ratio(const std::string& picker_id, double t, const Eigen::Vector2d& z, const Eigen::Vector2d& mean,
               const Eigen::Matrix2d& covariance, const topology::TopologicalMap& map,
               const PickerAssociationOptions& options) const;
  std::size_t size() const;
  void clear() { items_.clear(); }

 private:
  struct Item {
    double stamp = 0.0;
    std::unordered_map<topology::NodeIndex, double> likelihood;  // unlisted nodes: 0
  };
  std::map<std::string, std::map<std::string, Item>> items_;  // picker -> "sensor|robot" -> newest
};

struct AssociationResult {
  core::Observation observation;      // the detection: identifying (picker_id set) or unchanged (anonymous)
  int picker = -1;                    // index of the identified picker, -1 when anonymous
  std::vector<double> probabilities;  // p_i per picker
  double clutter_probability = 1.0;   // c / (c + sum_j l_j)
  bool concerns_nobody = false;       // anonymous and no picker reaches min_candidate_probability: not
                                      // published (it is nobody we track)
  BiasUpdate bias;                    // the identified picker's bias update (accepted or why not)
};

// Associates one anonymous observation carrying a position (LegPipeline::observation) with the pickers.
// `pickers[i]` and `beliefs[i]` describe picker i (beliefs may be shorter: missing ones are not used). An
// identified detection updates that picker's bias (GnssIngest::addSighting). An observation without a
// position, an identifying one or association disabled returns it unchanged. `evidence` (may be null)
// multiplies each l_i by IdentityEvidence::ratio.
AssociationResult associatePerson(const core::Observation& person, const std::vector<GnssIngest*>& pickers,
                                  const std::vector<BeliefView>& beliefs, const topology::TopologicalMap& map,
                                  const PickerAssociationOptions& options,
                                  const IdentityEvidence* evidence = nullptr);

// The people one sensor saw at one instant, associated jointly (Bar-Shalom's joint probabilistic data
// association): a joint event names each person one picker or clutter and each picker at most one person, its
// weight the product of their l_i (c for clutter); p_ji sums the weights of the events with person j ->
// picker i. One person: exactly associatePerson's l_i / (c + sum l). People within kSamePersonDistance of
// each other are taken as one person seen twice (a robot's two lasers) and are not made exclusive. Events are
// enumerated over the pickers a person could be (single-person probability >= 1e-4); a group of more than
// 200,000 events keeps the single-person probabilities. Bias sightings follow all the decisions. Results in
// the order of `people`.
constexpr double kSamePersonDistance = 0.5;  // m
std::vector<AssociationResult> associatePeople(const std::vector<core::Observation>& people,
                                               const std::vector<GnssIngest*>& pickers,
                                               const std::vector<BeliefView>& beliefs,
                                               const topology::TopologicalMap& map,
                                               const PickerAssociationOptions& options,
                                               const IdentityEvidence* evidence = nullptr);

// An identifying observation of a sensor in bias_sighting_sensors (RFID, UWB) with a metric position is a
// sighting of its picker: GnssIngest::addSighting with the observation's position and covariance. Returns
// whether it was used (false: not such an observation, unknown picker, or refused by the estimate).
bool addIdentifyingSighting(const core::Observation& obs, const std::vector<GnssIngest*>& pickers);

}  // namespace sensors
}  // namespace picker_localisation
