// The Topological Particle Filter of Navigate-and-Seek (Sec. IV, Algorithm 1, Eqs. 1-12): a belief over the
// nodes of a topological map, one filter per picker. ROS-free; time comes from observation stamps only and
// every random draw from the filter's own std::mt19937_64.
//
// Usage:
//   auto map = std::make_shared<const topology::TopologicalMap>(topology::loadMap(path));
//   TopologicalParticleFilter tpf(map, TpfParams::fromYamlFile("config/tpf.yaml"), /*seed=*/1);
//   UpdateResult r = tpf.update(observation);   // Algorithm 1 (initialises on the first accepted one)
//   tpf.predictTo(stamp);                        // periodic prediction when nothing arrives
//   const Belief& b = tpf.belief();              // sparse node masses, MAP node (Eq. 10), entropy, JSD ...
//
// Update cost: O(particles + support of the observation + degree); nothing per update is O(|N|). The filter
// owns two |N|-sized scratch arrays allocated once at construction that are kept all-zero between updates
// and only touched at the nodes that hold particles or likelihood.
//
// Interpretation choices where the paper is vague (details at the code):
//  * Eqs. 2/3: Eq. 3 read literally (softmax of exp(lambda*tau)) gives the LARGEST probability to nodes
//  against
//    the velocity (lambda = 0), contradicting the text ("null probability to those in the opposite
//    direction"). We use the decomposition of Eq. 2 itself: P(jump to k) = b_k (1 - exp(lambda_k tau)) / sum
//    b, so the total jump probability is exactly Eq. 2 and nodes with b_k = 0 are never chosen.
//  * Turning (Eq. 2 is 0/0 when no edge has a positive projection): when no edge lies within
//    acos(turn_projection_fraction) (78 deg) of the velocity -- a lane end, a corner into the headland --
//    every edge gets b_k = |v|, so the particle can turn and Eq. 7 rotates its velocity along the edge taken.
//    With a forward edge present, edges against the velocity keep probability 0. turn_projection_fraction =
//    0: such particles stay (they would wait for a re-initialisation, as nothing else changes their
//    velocity).
//  * tau in Eq. 2 is the dwell time at the prediction instant (tau_t + dt); at most one jump per prediction.
//    Eq. 2 is applied afresh at every prediction (the paper read literally): particles move faster the more
//    often sensors report; a "step-consistent" reading (the conditional jump probability since the last
//    step) tracked worse with 1 Hz GNSS in our lane-walk trials and was removed (CHANGELOG).
//  * Eq. 7: on a jump the observed velocity is (p(q') - p(q)) / max(tau_t + dt, min_jump_dwell) (a vector
//  along
//    the edge) and v' = v + Pr(q') (v_obs - v) / V with Pr(q') the Eq. 2-3 probability of the transition
//    taken at the dwell reached (transitionProbabilities(), independent of the step length); a particle that
//    stays keeps its velocity (the literal d = 0 case would decay it towards 0 while waiting).
//  * Eq. 8: L enters normalised to its maximum (likelihood scale is arbitrary, see core::Observation), the
//    Gaussian g is unnormalised (peak 1) with sigma = max(|v^s|/2, min_velocity_sigma); w_v = 0 when the
//    observation carries no velocity.
//  * All weights zero (support disjoint from the particles, no velocity): equal weights instead, so the
//    predicted particles are kept up to the Eq. 12 noise (unconnected jumps with p_rj still happen, which is
//    how Khan's unconnected variant recovers from a wrong lane); status kAccepted, reason "no overlap".
//  * JSD re-initialisation (Alg. 1 l. 6) also requires the observation to contradict the particles: the mean
//    of L / max L over the predicted particles below reinit_max_mean_likelihood (0.1). A flat
//    negative-information likelihood (RFID "not read here": 1 - p_detect near the antenna, 1 elsewhere) has
//    JSD ~0.98 to a concentrated belief although it agrees with it; re-initialising from it would spread the
//    belief over the whole map. 1.0 = the paper's rule (JSD alone).
//  * JSD (base-2 logs, so in [0, 1]) and entropy H (nats) over the support present. p_rj follows Algorithm 1:
//    set to unconnected_jump_probability at start and on re-initialisation, to 0 once H < epsilon_H.
//  * Eq. 12 velocity noise: inverse-transform sampling on a 4,096-quantile grid of N(0, 1) (speed; see code).
//  * Late observations: stamp < last update stamp but within reorder_window are fused at the current time
//    with no prediction (status kReordered); older ones are dropped and counted (kDroppedTooOld). The filter
//    never predicts backwards.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/topology/topological_map.h"
#include "picker_localisation/tpf/tpf_params.h"

namespace picker_localisation {
namespace tpf {

// One particle (Sec. IV: p = <q, v, tau, T, V>; T and V are shared by the filter), plus the lane-change path
// index, the last lane change completed (TpfParams::lane_change_keep_side) and the GNSS bias state
// (TpfParams::gnss_bias_state) and that bias's recent path (TpfParams::lane_swap_memory): 48 bytes. Single
// precision is ample for speeds (m/s), dwell times (s) and biases (m) and halves the memory traffic of
// resampling.
struct Particle {
  topology::NodeIndex node = topology::kInvalidNode;  // q
  float vx = 0.0f, vy = 0.0f;                         // v, m/s, map frame
  float dwell = 0.0f;                                 // tau, s
  std::uint32_t lane_change = 0;  // 1 + index of the lane-change path being walked (0: none); see TpfParams
  std::uint32_t last_lane_change = 0;  // 1 + index of the last lane-change path completed (0: none yet)
  float bias_x = 0.0f, bias_y = 0.0f;  // GNSS device bias b given this particle's path, m, map frame
  float bias_variance = -1.0f;         // per-axis variance of b, m^2; < 0: not started (next GNSS prior)
  // Evidence of the bias path for lane swaps (TpfParams::lane_swap_memory): the integral of (b - m) dt and of
  // dt over the recent fixes, each forgotten with the memory's time constant.
  float bias_integral_x = 0.0f, bias_integral_y = 0.0f;  // m s
  float bias_time = 0.0f;                                // s
  bool standing = false;  // TpfParams::stand_rate: the particle does not move; its speed is 0 to Eq. 8
};

enum class UpdateStatus {
  kAccepted,         // predicted to the stamp, weighted, resampled
  kReordered,        // late (within reorder_window): fused at the filter's current time without prediction
  kDroppedTooOld,    // older than the last update by more than reorder_window: ignored, counted
  kIgnoredSensor,    // sensor not in accepted_sensors (e.g. LiDAR in Khan mode): ignored, counted
  kRejectedInvalid,  // malformed (NaN, node out of range, sizes differ, nothing positive ...): ignored
};
const char* toString(UpdateStatus s);

struct UpdateResult {
  UpdateStatus status = UpdateStatus::kAccepted;
  std::string reason;          // empty on success; one line otherwise
  bool initialised = false;    // this observation initialised the filter (Eq. 1, first observation)
  bool reinitialised = false;  // the JSD monitor re-initialised the filter (Algorithm 1 l. 6-9)
  bool ok() const { return status == UpdateStatus::kAccepted || status == UpdateStatus::kReordered; }
};

struct FilterCounters {
  std::uint64_t accepted = 0, reordered = 0, dropped_too_old = 0, ignored_sensor = 0, rejected_invalid = 0;
  std::uint64_t reinitialisations = 0, predictions = 0, no_overlap = 0;
  std::uint64_t someone_else = 0;  // anonymous observations left unweighed (TpfParams::anonymous_min_support)
  std::uint64_t lane_evidence_projections =
      0;  // lane evidence that moved particles (lane_evidence_projection)
};

// The belief after the last update or prediction.
struct Belief {
  bool initialised = false;
  double stamp = 0.0;                      // s, stamp of the last update / prediction
  std::vector<topology::NodeIndex> nodes;  // support (nodes holding particles), ascending index
  std::vector<double> masses;              // normalised topological mass per node (Eq. 9), sums to 1
  // n* (Eq. 10; by lane first with TpfParams::map_node_by_lane); ties -> lowest index
  topology::NodeIndex map_node = topology::kInvalidNode;
  double entropy = 0.0;        // H of the particles' node distribution, nats (Alg. 1 l. 12)
  double jsd = 0.0;            // JSD of the last observation vs the predicted particles, [0, 1]
  bool reinitialised = false;  // the last update re-initialised the particles
  double unconnected_jump_probability = 0.0;  // current p_rj
  std::size_t particle_count = 0;
  std::uint64_t observations = 0;              // observations fused since construction / reset
  double massOf(topology::NodeIndex n) const;  // 0 outside the support
};

class TopologicalParticleFilter {
 public:
  // Throws std::invalid_argument on a null/empty map or invalid params (TpfParams::validate()).
  TopologicalParticleFilter(std::shared_ptr<const topology::TopologicalMap> map, TpfParams params,
                            std::uint64_t seed);

  // Algorithm 1 for one observation. Never throws on bad input: returns the status and reason instead and
  // leaves the belief untouched. association_probability: the probability that an observation naming no
  // picker is this filter's picker (core::associationProbability; TpfParams::weigh_anonymous_by_association);
  // ignored for identifying observations.
  UpdateResult update(const core::Observation& obs, double association_probability = 1.0);
  // Prediction only (Eqs. 2-7) to `stamp` (periodic prediction). No-op returning false before the first
  // observation or when stamp is not after the last update.
  bool predictTo(double stamp);
  // Forget everything: the next observation initialises the filter again (Eq. 1).
  void reset();
  // The map was edited at run time: the filter moves to `map`, each particle to old_to_new[its node]
  // (topology::compareMaps: the node of the same name, else the one nearest to where it was). Velocities,
  // dwell times and GNSS bias states are kept; lane-change paths and side memory, which index the old graph's
  // paths, are forgotten (the next lane end starts them again). Throws std::invalid_argument on an empty map
  // or a mapping that is not one new node per old node.
  void adoptMap(std::shared_ptr<const topology::TopologicalMap> map,
                const std::vector<topology::NodeIndex>& old_to_new);

  const Belief& belief() const { return belief_; }
  const FilterCounters& counters() const { return counters_; }
  const std::vector<Particle>& particles() const { return particles_; }
  const TpfParams& params() const { return params_; }
  const topology::TopologicalMap& map() const { return *map_; }
  bool initialised() const { return belief_.initialised; }
  double lastStamp() const { return belief_.stamp; }

  // --- what-if (planner): work on a copy, the live filter is untouched ------------------------------------
  // A copy whose generator is re-seeded with `seed` (0: the copy keeps the live generator's state).
  TopologicalParticleFilter copyWithSeed(std::uint64_t seed) const;
  // A copy re-seeded with `seed` and predicted `seconds` (>= 0) beyond the last update: where predictAhead
  // and posteriorUnder start from (a planner asking several hypotheses at one horizon predicts once).
  TopologicalParticleFilter predictedCopy(double seconds, std::uint64_t seed = 0) const;
  // Belief after predicting `seconds` (>= 0) beyond the last update.
  Belief predictAhead(double seconds, std::uint64_t seed = 0) const;
  // Belief after fusing `hypothetical` into a copy of this filter at its last stamp (the observation's stamp
  // is ignored): posteriorUnder without the prediction, for a predictedCopy().
  Belief posteriorNow(const core::Observation& hypothetical, UpdateResult* result = nullptr) const;
  // Belief after predicting `seconds` ahead and fusing `hypothetical` at that time (its stamp is ignored).
  // An invalid hypothetical observation returns the predicted belief; `result` (optional) tells why.
  Belief posteriorUnder(const core::Observation& hypothetical, double seconds = 0.0, std::uint64_t seed = 0,
                        UpdateResult* result = nullptr) const;

  // --- the equations, exposed for tests and the planner ---------------------------------------------------
  // Eq. 6: lambda = 2 log(1/2) max(0, proj) / d (1/s, <= 0). proj = v . (p_k - p_q)/|p_k - p_q|.
  static double lambda(double projected_speed, double distance);
  // Un-normalised jump probability of one edge in Eq. 2: 1 - exp(lambda * tau).
  static double edgeJumpProbability(double lambda, double dwell);
  // Eq. 2 for particle state (node, velocity, dwell): probability of leaving the node.
  double jumpProbability(topology::NodeIndex node, double vx, double vy, double dwell) const;
  // Eq. 2-3 per neighbour: probability of having jumped to each motion neighbour of `node` after dwelling
  // `dwell` (same order as motionNeighbours(node)); sums to jumpProbability().
  std::vector<double> transitionProbabilities(topology::NodeIndex node, double vx, double vy,
                                              double dwell) const;
  // Eq. 8 weight of a particle for a likelihood value L^ in [0, 1] (already normalised to its maximum).
  double particleWeight(const Particle& p, double normalised_likelihood, const core::Observation& obs) const;
  // JSD (base 2) between two sparse distributions given as (node, probability) lists (each summing to 1).
  static double jensenShannonDistance(const std::vector<std::pair<topology::NodeIndex, double>>& p,
                                      const std::vector<std::pair<topology::NodeIndex, double>>& q);
  // Entropy (nats) of a distribution given by its probabilities.
  static double entropy(const std::vector<double>& probabilities);

 private:
  struct MotionGraph;  // CSR adjacency with unit edge directions and lengths, shared by copies

  // Makes `map` the filter's map with its motion graph, bias fix variance and scratch buffers (constructor,
  // adoptMap); on an exception (std::bad_alloc) nothing has changed.
  void useMap(std::shared_ptr<const topology::TopologicalMap> map);
  UpdateResult reject(UpdateStatus status, std::string reason);
  void initialise(const core::Observation& obs);
  void reinitialisePart(const core::Observation& obs, double fraction);
  void redraw(const core::Observation& obs, std::size_t count);  // Eq. 1 for `count` evenly spread particles
  void predict(double dt);
  void predictFixedLambda(double dt);                    // Khan et al. 2020's fixed-rate motion
  void reverseSomeVelocities(double dt);                 // mid-lane turns (reverse_rate)
  void switchStanding(double dt);                        // stops and starts (stand_rate, walk_rate)
  void moveWithVelocityModel(std::size_t i, double dt);  // Eqs. 2-7 for particle i
  topology::NodeIndex projectOnEdges(Particle& p);
  void jumpAlong(Particle& p, std::uint32_t arc, double pr, double tau, topology::NodeIndex path_next);
  double observationJsd(const core::Observation& obs, double sum_likelihood, double max_likelihood,
                        double* mean_likelihood);
  // false: no overlap; equal_weights: the observation is not weighed (the no-overlap resampling)
  // association_probability < 1: a PDA update (TpfParams::weigh_anonymous_by_association).
  bool weightAndResample(const core::Observation& obs, double max_likelihood, bool equal_weights = false,
                         double association_probability = 1.0);
  // GNSS bias state: predictive density of the fix per particle (into weights_, scaled to max 1), then the
  // per-particle Kalman update of b. Only for observations with usesBiasState(sensor), a position and a
  // prior.
  void weighWithBiasState(const core::Observation& obs);
  // Lane hypotheses kept alive after resampling on a GNSS fix with the bias state
  // (TpfParams::lane_swap_rate).
  void swapLanes(const core::Observation& obs);
  // Lane evidence (TpfParams::lane_evidence_sensors): lane_evidence_sweeps Metropolis-Hastings sweeps of the
  // swap move with the observation's likelihood (node_scratch_a_) in the acceptance. True when a particle
  // moved.
  bool moveTowardsLaneEvidence();
  // TpfParams::lane_evidence_projection: moves particles across into the lane whose nodes have the max
  // likelihood (node_scratch_a_); returns how many moved.
  std::size_t projectOntoLaneEvidence(double max_likelihood);
  // The device prior both lane moves weigh a shifted bias with (the last fix with the bias state): its mean,
  // 1 / 2P and the path term's Q / 8P^2; all 0 before such a fix.
  struct SwapPrior {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    double inv_two_p = 0.0, inv_four_p_tau = 0.0;
    bool known() const { return inv_two_p > 0.0; }
  };
  SwapPrior swapPrior() const;
  // log of the device prior's density ratio for shifting a particle's bias (and its recent path) by `shift`.
  double swapLogPriorRatio(const Particle& p, const Eigen::Vector2d& shift, const SwapPrior& prior) const;
  // True when this GNSS fix may run the lane swaps: the map has adjacent lanes, lane_swap_rate > 0 and no
  // other sensor observed the picker within lane_swap_memory (the device prior, swapPrior().known(), is the
  // caller's to check).
  bool swapsRun(const core::Observation& obs) const;
  // Gives `weight` to p's node and to the nodes across from it in the other lanes, in proportion to the
  // device prior's density of each shifted bias and path (TpfParams::lane_masses_by_swap_prior);
  // deposit(node, mass).
  template <typename Deposit>
  void shareOverLanes(const Particle& p, double weight, const SwapPrior& prior, Deposit&& deposit) const;
  // Walking across the lanes through the swap neighbours: the node one lane beyond `current` in the direction
  // from `previous` to `current`; kInvalidNode at the last lane.
  topology::NodeIndex nextAcross(topology::NodeIndex previous, topology::NodeIndex current) const;
  // Moves a particle to `to` with its bias (and bias path) shifted by `shift`.
  static void applySwap(Particle& p, topology::NodeIndex to, const Eigen::Vector2d& shift);
  void resample(double total_weight);
  void chooseMapNodeByLane();  // TpfParams::map_node_by_lane
  void addNoise();
  void recordBelief(bool counted);
  void fuse(const core::Observation& obs, double dt, UpdateResult& result, double association_probability);

  std::shared_ptr<const topology::TopologicalMap> map_;
  std::shared_ptr<const MotionGraph> graph_;
  TpfParams params_;
  std::uint64_t seed_;
  std::mt19937_64 rng_;

  std::vector<Particle> particles_;
  std::vector<Particle> resampled_;  // scratch, same size as particles_
  std::vector<double> weights_;      // per particle, scratch
  // |N|-sized scratch, all zero between calls (touched entries are cleared after use).
  std::vector<double> node_scratch_a_, node_scratch_b_;
  std::vector<topology::NodeIndex> touched_;
  std::vector<double> lane_scratch_;        // per lane, all zero between calls (chooseMapNodeByLane)
  std::vector<double> edge_scratch_;        // per-edge jump contributions of one particle (max degree)
  std::vector<double> projection_scratch_;  // per-edge projections b of one particle (max degree)
  std::vector<std::uint32_t> spare_bits_;   // per particle: random bits of the prediction draw used by Eq. 12

  double unconnected_p_ = 0.0;      // p_rj
  double bias_stamp_ = 0.0;         // s, stamp the particles' bias variances were last predicted to
  double bias_step_ = 0.0;          // s, time since the previous fix with the bias state (0 at the first)
  // s, last observation of a sensor without the bias state (-inf: none)
  double other_sensor_stamp_ = -std::numeric_limits<double>::infinity();
  double bias_fix_variance_ = 1.0;  // m^2, R of the bias state's fix model (constructor)
  // The device model of the last fix with the bias state (mean m, per-axis variance P, drift rate Q): what
  // the lane swaps and a lane-evidence move weigh the shifted bias with (P 0: none yet).
  Eigen::Vector2d bias_prior_mean_ = Eigen::Vector2d::Zero();
  double bias_prior_variance_ = 0.0;
  double bias_drift_rate_ = 0.0;
  Belief belief_;
  FilterCounters counters_;
};

}  // namespace tpf
}  // namespace picker_localisation
