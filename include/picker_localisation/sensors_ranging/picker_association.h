// Identity for anonymous people detections (issue "Find the lane", seed 001 Sec. VI). ROS-free.
//
// A confirmed person from the LiDAR (or camera-fused legs) names nobody. Each picker predicts where it is from
// two sources:
//   g_i(z) = N(z; fix_i - bias_i, P_bias_i + residual^2 I + (speed age)^2 I + R_z)   bias-corrected fix
//   b_i(z) = sum_n m_i(n) N(z; x_n, belief_sigma^2 I + R_z)                           tracker's belief
// and the detection's likelihood under "it is picker i" is the mixture l_i = (1 - w) g_i + w b_i (either term
// alone when the other is missing). A mixture, not a product: the belief was built from the same fixes, and a
// confidently wrong belief must not veto the fix (that is the lane we want to correct). Against the
// hypothesis "nobody we track" (clutter density c: false legs, other workers) the association probabilities
// are p_i = l_i / (c + sum_j l_j) (one detection, one picker at most: the standard single-scan PDA form).
// p_i >= min_probability makes the detection an identifying observation of picker i and a metric sighting for
// its bias estimate; anything less stays anonymous, for the trackers of the pickers whose p_i reaches
// association_min_candidate_probability (Observation::candidate_pickers; none: not published at all). Before the first
// sighting the bias prior is wide (sqrt(offset_std^2 + drift_std^2) = 3.2 m per axis), so only a detection that
// is both near the fix and far from every other picker is identified; once identified, the corrected fix is
// sharp and the next sightings follow.
#pragma once

#include <deque>
#include <string>
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
  // Stores a copy when `stamp` is newer than the newest kept (an equal stamp replaces it); keeps `horizon` s.
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
// identified detection updates that picker's bias (GnssIngest::addSighting). An observation without a position,
// an identifying one or association disabled returns it unchanged.
AssociationResult associatePerson(const core::Observation& person, const std::vector<GnssIngest*>& pickers,
                                  const std::vector<BeliefView>& beliefs, const topology::TopologicalMap& map,
                                  const PickerAssociationOptions& options);

// An identifying observation of a sensor in bias_sighting_sensors (RFID, UWB) with a metric position is a
// sighting of its picker: GnssIngest::addSighting with the observation's position and covariance. Returns
// whether it was used (false: not such an observation, unknown picker, or refused by the estimate).
bool addIdentifyingSighting(const core::Observation& obs, const std::vector<GnssIngest*>& pickers);

}  // namespace sensors
}  // namespace picker_localisation
