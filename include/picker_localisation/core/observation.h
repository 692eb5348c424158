// A sensor observation of a picker as the filters consume it: a sparse likelihood over map nodes
// (Navigate-and-Seek Sec. IV: "each observation from sensor s is passed to the filter in the form of a
// likelihood distribution L(N) ... paired with a variable id_s"). ROS-free.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace core {

struct Observation {
  double stamp = 0.0;            // s, the measurement's own time stamp (never the wall clock)
  std::string sensor;            // gnss | lidar | rfid | uwb | camera | ... (selects per-sensor gammas)
  std::string robot_id;          // robot whose sensor produced it; empty for picker-worn devices
  std::string picker_id;         // identified picker; empty when !identifying
  bool identifying = false;
  // Not identifying: the pickers it may concern, e.g. those an anonymous person could be (association
  // probability above a floor); empty = every picker (paper Sec. VI: anonymous observations reach every
  // filter). A person the association named: picker_id alone, with the probability it was named at.
  std::vector<std::string> candidate_pickers;
  // Parallel to candidate_pickers, or empty: the association probability that the observation is each of them
  // (gnss_ingest's p_i). A tracker weighs the observation by it (TpfParams::weigh_anonymous_by_association,
  // weigh_named_by_association).
  std::vector<double> candidate_probabilities;
  std::vector<topology::NodeIndex> nodes;  // support of the likelihood (unique indices)
  std::vector<double> likelihood;          // >= 0, one per entry of nodes; need not sum to 1
  std::optional<Eigen::Vector2d> velocity;  // m/s, map frame
  std::optional<Eigen::Vector2d> position;  // metric position the likelihood came from, map frame, m
  Eigen::Matrix2d position_covariance = Eigen::Matrix2d::Zero();  // m^2
  // GNSS fixes (gnss_ingest): the device bias estimate that was subtracted from the raw fix (raw fix = position +
  // bias_removed; zero before any sighting), that estimate's covariance (the bias prior before any sighting) and
  // how fast the bias wanders (2 drift_std^2 / drift_tau, m^2/s per axis). The TPF's per-particle bias state
  // starts from them (tpf_params.h, gnss_bias_state). Empty for other sensors.
  std::optional<Eigen::Vector2d> bias_removed;
  Eigen::Matrix2d bias_covariance = Eigen::Matrix2d::Zero();  // m^2
  double bias_drift_rate = 0.0;                               // m^2/s per axis

  bool empty() const { return nodes.empty(); }
  double totalLikelihood() const;
};

// True when the observation is for `picker_id`'s filter: its identified picker, or (not identifying) one of its
// candidate pickers, or every picker when it names none.
bool concernsPicker(const Observation& obs, const std::string& picker_id);
// The same rule on the fields (for a message, before converting it).
bool concernsPicker(bool identifying, const std::string& identified, const std::vector<std::string>& candidates,
                    const std::string& picker_id);

// The probability that the observation is `picker_id` for that picker's filter: the candidate's entry of
// candidate_probabilities (0 when the picker is not a candidate); 1 when the observation carries no
// probabilities (it is simply given to the filter), or identifies the picker without listing it (a tag read).
// A people detection the association named carries its picker and that probability as its one candidate.
double associationProbability(const Observation& obs, const std::string& picker_id);

// Negative-information form: every node of a map of `num_nodes` listed, with likelihood 1 (the caller then
// lowers the nodes the evidence concerns, e.g. an antenna that did not read, a laser that saw nobody).
void setLikelihoodOverEveryNode(Observation& obs, std::size_t num_nodes);

// Options of a Gaussian node likelihood.
struct GaussianLikelihoodOptions {
  double cutoff_sigmas = 3.0;     // nodes farther than this many (largest) standard deviations are left out
  double min_sigma = 0.0;         // floor on each standard deviation, m
  std::size_t max_nodes = 0;      // keep at most this many most likely nodes (0: no limit)
};

// L(n) = exp(-0.5 d^T C^-1 d), d = node position - mean, over the nodes within the cut-off (k-d tree range
// query: the cost does not grow with the map size). When no node lies within the cut-off the nearest node gets
// the likelihood instead, so an observation is never empty. The covariance is regularised to be positive
// definite with the sigma floor.
void setGaussianLikelihood(Observation& obs, const topology::TopologicalMap& map, const Eigen::Vector2d& mean,
                           const Eigen::Matrix2d& covariance, const GaussianLikelihoodOptions& options = {});

// Checks an observation against a map: indices in range, values finite and >= 0, sizes equal, something
// positive. Returns an empty string when valid, else the reason.
std::string validateObservation(const Observation& obs, const topology::TopologicalMap& map);

// True when `c` is a 2x2 covariance: finite, symmetric and positive semi-definite, up to a tolerance relative to
// its largest entry (a rank-1 covariance of large variances is PSD only up to rounding). The one check every
// node applies to a covariance it receives.
bool isCovariance2d(const Eigen::Matrix2d& c);

// Scales non-negative masses to sum to 1, through their largest first, so masses near the double's range
// ([1e308, 1e308]) do not sum to infinity and all become 0. False, masses unusable, when the largest is not
// finite and positive. The one normalisation of beliefs a node receives.
bool normaliseMasses(std::vector<double>& masses);

}  // namespace core
}  // namespace picker_localisation
