// Parameters of the Topological Particle Filter (Navigate-and-Seek Sec. IV, Table I) and the baselines /
// ablations of Table II expressed as parameter presets (never code forks). ROS-free.
//
// Defaults are Table I; config/tpf.yaml documents every field with its meaning and unit.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace picker_localisation {
namespace tpf {

// Per-sensor weighting factors of Eq. 8.
struct SensorGamma {
  double node = 1.0;      // gamma^s_q: weight of the node likelihood term w_q
  double velocity = 0.0;  // gamma^s_v: weight of the velocity agreement term w_v
};

// How particles move between nodes.
enum class MotionModel {
  kVelocity,     // Eqs. 2-7: lambda from the particle velocity projected on each edge (Eq. 6), velocity state
                 // updated over the window V (Eq. 7); the full TPF.
  kFixedLambda,  // Khan et al. [1] Eq. 2 / ConstantSpeed ablation: jump probability 1 - exp(-fixed_lambda *
                 // tau) to a uniformly chosen neighbour; particle velocity neither used nor estimated, w_v =
                 // 0.
};

enum class ResamplingScheme {
  kLowVariance,  // systematic / low-variance resampling (one uniform draw per resampling), default
  kMultinomial,  // independent draws (Eq. 11 read literally)
};

struct TpfParams {
  // Upper bounds a farm can afford, checked by validate() for the file and for a picker's run-time overrides
  // alike: one picker's filter must not starve the others of a shared tracker. 100,000 particles are about
  // 14 MB and 100 times the default's update time; predictions faster than 10 Hz only repeat what the
  // observations (GNSS 1-10 Hz) tell; a lane-change path of 50 hops is longer than any farm's headland.
  static constexpr std::size_t kMaxParticles = 100000;
  static constexpr double kMaxPredictionRate = 10.0;  // Hz
  static constexpr int kMaxLaneChangeHops = 50;

  // --- particles -----------------------------------------------------------------------------------------
  std::size_t num_particles = 1000;
  ResamplingScheme resampling = ResamplingScheme::kLowVariance;

  // --- Eq. 1, initialisation (Table I) ---------------------------------------------------------------------
  double velocity_init_mean = 0.0;       // mu_init, m/s, per component
  double velocity_init_variance = 5e-2;  // sigma^2_init, (m/s)^2, per component
  double dwell_init_min = 0.0;           // tau^-_init, s
  double dwell_init_max = 1.0;           // tau^+_init, s

  // --- Eq. 12, resampling noise (Table I) ------------------------------------------------------------------
  double velocity_noise_mean = 0.0;       // mu_noise, m/s
  double velocity_noise_variance = 5e-4;  // sigma^2_noise, (m/s)^2
  double dwell_noise_min = -0.1;          // tau^-_noise, s
  double dwell_noise_max = 0.1;           // tau^+_noise, s

  // --- Eqs. 2-7, prediction --------------------------------------------------------------------------------
  MotionModel motion_model = MotionModel::kVelocity;
  double fixed_lambda = 0.1;      // 1/s, Khan et al.'s constant rate (kFixedLambda only)
  double velocity_window = 10.0;  // V of Eq. 7 (dimensionless number of steps; not in Table I)
  double min_jump_dwell = 0.1;    // s, floor on the dwell time used for the observed speed of Eq. 7
  bool directed_motion = false;   // true: particles follow file edge direction; false: undirected graph
  // A particle whose velocity projects on no edge by at least this fraction of its speed (no edge within
  // acos(0.2) = 78 deg: lane end, corner) treats every edge as aligned (b = |v|) so it can turn. 0: it stays.
  double turn_projection_fraction = 0.2;
  // true: on a jump, Eq. 7 smooths the particle's speed and its heading becomes the direction of the edge
  // taken (the particle walks the graph). false (paper literal): Eq. 7 blends the velocity vector by 1/V, so
  // after a turn the velocity points the old way for about V jumps.
  bool velocity_follows_edge = true;
  // 1/s, rate at which a particle turns round (velocity negated) between nodes, for pickers who walk back
  // along the lane (Table I p_reverse); 0: only lane ends and corners turn a particle (paper).
  double reverse_rate = 0.01;
  // Standing (not in the paper): pickers stop for minutes (picking a bush, packing trays, waiting for the
  // robot they called). A walking particle stops at stand_rate (1/s) and a standing one walks on at walk_rate
  // (1/s); a standing particle does not jump and its speed is 0 to the velocity term of Eq. 8. Without it
  // every particle keeps walking at its smoothed speed, and the cloud that best explains a picker standing
  // near a lane end bounced about the headland (docs/readme/tpf.md). 1/(1 + 10) of the particles stand while
  // nothing says the picker stands; a stop lasts 20 s unless the fixes keep it. stand_rate 0: always walk
  // (paper).
  double stand_rate = 0.005;
  double walk_rate = 0.05;
  // Anonymous people (not in the paper, whose LiDAR people reach every tracker): an observation that names no
  // picker (identifying false; gnss_ingest's candidates for it) and that the particles explain with a mean
  // L / max L below this (0.001: less than one particle of 1000 at its peak) is taken to be someone else, and
  // leaves the belief as a no-overlap update does; otherwise the few particles its likelihood's tail reaches
  // take the whole cloud. Higher values (0.005) also refused the sightings that pull a lost belief into its
  // picker's lane (docs/readme/tpf.md). 0: every anonymous observation weighs the particles (paper).
  double anonymous_min_support = 0.001;
  // Anonymous people weighed by their association probability (not in the paper; the probabilistic data
  // association update, Bar-Shalom and Tse 1975): an observation naming no picker that gnss_ingest found to
  // be this picker with probability rho (Observation::candidate_probabilities) weighs particle i by (1 - rho)
  // mean_j w_j + rho w_i (w the Eq. 8 weight), the likelihood of "someone else, or this picker", so after the
  // update the mass its likelihood pulls is rho, not 1. Off: every candidate's tracker takes the person as
  // certainly its picker (the paper's anonymous observations). Observations without probabilities are taken
  // as certain.
  bool weigh_anonymous_by_association = true;
  // The same update for a person the association named this picker (p >= association_min_probability): it
  // pulls p of the mass, not all, so a wrong name (a neighbour p thought to be this picker) leaves 1 - p
  // where it was. Off: a named person is certain (the paper's identifying observations). Tag reads are
  // certain.
  bool weigh_named_by_association = false;
  // Lane-change structure of the farm (not in the paper; Polvara et al. 2021, Sec. VI: pickers walk on into the
  // adjacent lane). For every lane end the filter finds, from the map's topology alone, the shortest path through
  // non-lane nodes to the nearest end of the adjacent lane on each side (at most lane_change_max_hops hops).
  // A particle that leaves its lane at an end takes one of these paths (the one its jump started on, else
  // one at random); while on it, its next jump follows the path with weight 1 against lane_change_leak for
  // every other edge, and it ends one node inside the new lane. Off: particles wander the headland as the
  // plain velocity model moves them. Velocity motion model only.
  bool lane_change_model = true;
  double lane_change_leak = 0.1;  // relative weight of the edges off the path, [0, 1]
  int lane_change_max_hops = 6;   // longest lane-change path searched, hops
  // Side memory (not in the paper): pickers work through a tunnel row after row in one direction, so a picker
  // that last moved to the lane on one side will likely move on to that side again. Each particle remembers
  // the direction of its last completed lane change; at a lane end, a side whose path agrees with it
  // (positive dot product of the two displacements) weighs lane_change_keep_side against 1 -
  // lane_change_keep_side for the other side (the back edge into the lane keeps its weight). 0.5: no memory,
  // each side equally likely.
  double lane_change_keep_side = 0.8;

  // --- GNSS bias per particle (not in the paper; Khan et al. 2020 Sec. VI) ----------------------------
  // A phone's fix is wrong by an almost constant 2-5 m: its errors are one slowly drifting bias, not
  // independent draws. Fusing N fixes as independent (Eq. 8 literal) counts that one bias N times, so a bias
  // of a lane spacing outvotes the lane carried by the motion model within a minute (mid-lane splits, lane
  // ends decided by the bias). With gnss_bias_state each particle carries the device bias b (x, y) and its
  // variance (a Rao-Blackwellised particle filter: a scalar Kalman filter per particle and axis). A fix z of
  // a particle at node position p weighs it by the predictive density N(z - p - b; 0, (var + R) I) and then
  // updates b: the lane is told by how the fixes *move* (a lane change shifts them by a lane spacing), not by
  // where they lie, unless the bias is known (after a sighting the prior from gnss_ingest is tight). The
  // device model is gnss_ingest's (bias_offset_std, bias_drift_std, bias_drift_tau), carried by each fix: new
  // or redrawn particles start from its prior (core::Observation::bias_removed / bias_covariance: the
  // estimate after a sighting, else the bias prior), and b is the Gauss-Markov process of that prior (mean
  // bias_removed, stationary variance bias_covariance, initial rate bias_drift_rate): every fix keeps
  // weighing the bias a lane implies against the device's known error size. Only observations of
  // gnss_bias_sensors that carry a position and a bias prior use it; others weigh with L as Eq. 8.
  bool gnss_bias_state = true;
  std::vector<std::string> gnss_bias_sensors{"gnss"};
  // m, per-axis spread of a fix about the particle's node once b is removed, besides where the picker is
  // between nodes (added from the map: node spacing^2 / 12): white noise, the picker across the lane,
  // particle lag.
  double gnss_bias_fix_std = 1.0;
  // Lane hypotheses kept alive (a Metropolis-Hastings move after resampling on fixes with the bias state; the
  // resample-move of Gilks and Berzuini 2001). Where fixes cannot tell two lanes apart (lanes 1.5 m apart, a
  // phone's bias 3 m), a particle in lane L with bias b explains every fix exactly as well as one in the
  // adjacent lane with bias b + the lane offset; only the device prior prefers one. Resampling alone lets the
  // particle counts of such near-equal hypotheses drift until one lane holds all particles, and nothing
  // brings the others back (no edge crosses a lane): pickers were held one lane off for whole walks. So each
  // particle in a lane proposes, at lane_swap_rate (1/s), to stand at the nearest node of the adjacent lane
  // on one side (at most lane_swap_max_distance away, across the lane axis) with its bias shifted so that it
  // predicts the same fixes, and the move is accepted with the ratio of the device prior's densities of the
  // two biases. The counts per lane then follow the evidence instead of resampling noise. Swaps pause for
  // lane_swap_memory after an observation of another sensor (a robot saw the picker): that lane evidence is
  // not in the bias path the acceptance weighs. 0: off.
  double lane_swap_rate = 0.2;
  double lane_swap_max_distance = 3.5;  // m
  // s, how long the bias path a swap is weighed on is remembered (exponential forgetting): the acceptance
  // also carries the Gauss-Markov path density of the recent biases, so evidence gathered over minutes (a
  // lane end, the farm's edge) is not undone by swaps that the current bias alone would allow.
  double lane_swap_memory = 600.0;
  // Lane evidence (a row the picker reported on a call): an observation of one of these sensors says which
  // lane, not where along it. Weighting alone cannot move a belief wholly in the neighbouring lane (it has no
  // particle in the reported one), so after resampling each particle makes lane_evidence_sweeps proposals of
  // the lane-swap move above (the adjacent lane on a random side, its bias shifted), accepted by the
  // observation's likelihood ratio L(n') / L(n) times the device prior's ratio of the two biases and of their
  // recent paths: a Metropolis-Hastings kernel whose invariant law is the posterior (resample-move, Gilks and
  // Berzuini 2001), so the lanes' mass follows the reported row and the GNSS evidence together (a mistyped
  // row next to a strongly-held lane does not win outright). 0 sweeps (default): none (the projection below
  // moves the belief). Measured off: with a row on every call (10 % a neighbour's) 4 sweeps gave no fewer
  // wrong-lane entries than weighting alone (docs/readme/tpf.md, "A reported row").
  std::vector<std::string> lane_evidence_sensors{"reported_row"};
  int lane_evidence_sweeps = 0;
  // Lane evidence moves particles instead of weighing them: each particle outside the evidence's lane (L
  // below its max) moves across, lane after lane through the swap neighbours, to the same place along that
  // lane with probability 1 - L(n) / max L, its bias shifted so that it predicts the same fixes; the others
  // stay and no weighting follows. The belief then holds the reported row with at least 1 - floor of its
  // mass, a mixture of "the row is right" (the belief moved, its along-lane place kept) and "the row is
  // mistyped" (the belief as it was), whatever the belief held before. Weighting cannot lift a lane no
  // particle holds, and the swap moves above, accepted against a device prior a wrong identity had made
  // tight, could not either (docs/readme/tpf.md, "A reported row"). The fixes that follow still weigh the
  // moved particles: a bias measured by a robot pulls a belief moved against it back within seconds, a stale
  // one does not.
  bool lane_evidence_projection = true;
  bool isLaneEvidence(const std::string& sensor) const;  // one of lane_evidence_sensors
  // The decision (Eq. 10's n*, the tracker's current_node, a dispatch target) by lane first, coarse to fine:
  // in a lane or not (the two totals), then the lane holding the most mass and its node of most mass, or else
  // the off-lane node of most mass. Eq. 10 literally (false) takes the single node of most mass: where the
  // belief is spread over a few lanes and many nodes along them (GNSS only), that node is a draw among
  // near-equal ones and its lane changes with the particle noise, while the lanes' totals are stable.
  bool map_node_by_lane = true;
  // The belief's masses on a GNSS fix that runs the lane swaps, Rao-Blackwellised over the lane: each
  // particle in a lane shares its weight between its node and the nodes across from it in every other lane
  // (through the swap neighbours, lane after lane), in proportion to the device prior's density of each
  // shifted bias and bias path (the conditional law of its lane given its along-lane place and bias path: the
  // same walk in another lane explains every fix alike). Counting particles instead leaves near-equal lanes
  // (a 2 m error over lanes 1.5 m apart) to resampling noise, and the decision by lane above then follows
  // that noise rather than the small but real preference of the device prior: pickers fell more than 0.2
  // below the raw fix's lane share on slowly drifting GNSS. Only where swaps run (not within lane_swap_memory
  // of another sensor's observation), so a belief with a robot's evidence is counted as before. Measured:
  // docs/readme/tpf.md.
  bool lane_masses_by_swap_prior = true;
  bool usesBiasState(const std::string& sensor) const;

  // --- Eq. 8, weighting ------------------------------------------------------------------------------------
  // Keyed by Observation::sensor. Table I: gnss (1, 1), lidar (0.25, 0), rfid (1, 0). Choices for sensors
  // the paper does not use: uwb (1, 0) like RFID (identifying range), camera (0.25, 0) like LiDAR.
  std::map<std::string, SensorGamma> sensor_gammas;
  SensorGamma default_gamma{0.25, 0.0};  // for a sensor missing from sensor_gammas (anonymous, low trust)
  // false (paper): w = w_q + w_v. true: w = w_q (1 + w_v), so velocity agreement scales the node term and a
  // particle outside the node likelihood's support keeps weight 0 whatever its velocity.
  bool velocity_weight_product = true;
  double min_velocity_sigma = 0.05;  // m/s, floor on sigma = |v^s| / 2 of the Gaussian of Eq. 8
  // Sensors this filter fuses; empty = all. Observations of other sensors are ignored (counted).
  std::vector<std::string> accepted_sensors;

  // --- Algorithm 1, monitors
  // ---------------------------------------------------------------------------------
  bool jsd_monitor = true;       // re-initialise when JSD > jsd_threshold on an identifying observation
  double jsd_threshold = 0.975;  // epsilon_JSD, [0, 1]
  // Re-initialise only if, in addition, the mean of L / max L over the predicted particles is below this
  // (the observation contradicts the belief; a flat negative-information likelihood does not). 1: JSD alone.
  double reinit_max_mean_likelihood = 0.1;
  // Share of the particles drawn again from the observation on a re-initialisation, (0, 1]; 1 = Alg. 1 (all).
  // 0.5: a fix that contradicts the particles keeps half of them where they were, so a belief a wrong
  // identity pulled a lane off is still redrawn at the fix while a right belief under a GNSS drift of a lane
  // within seconds (Table I: 1.7 m in 10 s, traced just after a robot's sighting) is not thrown away; the two
  // halves then compete on the evidence that follows. Measured (docs/readme/dispatch.md, the call scenario):
  // fewer wrong-lane entries on both farms, most on 135 m lanes (0.186 -> 0.114 per call, seeds 1..8).
  double reinit_fraction = 0.5;
  // Sensors whose identifying observations may re-initialise; empty = all (paper). Default {gnss, uwb, pose}:
  // measured (docs/readme/tpf.md), re-initialising from RFID reads 5-8 m away scatters a right belief over
  // several lanes (white-noise GNSS, rfid_gnss right-lane share 0.81 with RFID re-initialisations, 0.92
  // without; 0.89 when only 10 % of the particles are redrawn, reinit_fraction 0.1).
  std::vector<std::string> reinit_sensors;
  bool entropy_gate = true;                    // set p_rj to 0 once the entropy drops below entropy_threshold
  double entropy_threshold = 0.6;              // epsilon_H, nats
  double unconnected_jump_probability = 1e-3;  // p_rj at start and after each re-initialisation (Alg. 1 l. 8)

  // --- time ------------------------------------------------------------------------------------------------
  double prediction_rate = 0.25;  // Hz, periodic prediction when no observation arrives (used by the node)
  double reorder_window = 1.0;    // s, late observations within this window are fused at the current time

  TpfParams();  // fills sensor_gammas with the Table I values

  SensorGamma gammaFor(const std::string& sensor) const;
  bool acceptsSensor(const std::string& sensor) const;
  // Empty string when valid, else the first problem (one line).
  std::string validate() const;

  // Reads a YAML node with the keys of config/tpf.yaml (missing keys keep the defaults above; a `method`
  // key applies presetForMethod last, so the preset's mode switches win over the file's). Throws
  // std::runtime_error naming the key on a bad value. With `unknown`, one message per key that is none of
  // yamlKeys() is appended ("tpf params: unknown key 'x' (did you mean 'y'?)").
  static TpfParams fromYaml(const YAML::Node& node, std::vector<std::string>* unknown = nullptr);
  static TpfParams fromYamlFile(const std::string& path, std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();  // every key fromYaml reads, `method` included
  // Table II method names: "tpf" (full filter, default), "paper_tpf" (the paper's filter read literally:
  // sets velocity_follows_edge, velocity_weight_product, reverse_rate, lane_change_model, jsd_monitor,
  // reinit_fraction to the paper's reading), "khan_connected", "khan_unconnected", "no_monitor",
  // "constant_speed". A preset sets only its mode switches (motion_model, fixed_lambda, accepted_sensors,
  // jsd_monitor, entropy_gate, unconnected_jump_probability) on top of `base`.
  // Throws std::invalid_argument for an unknown name.
  static TpfParams presetForMethod(const std::string& method, const TpfParams& base = TpfParams());
  static std::vector<std::string> methodNames();
};

const char* toString(MotionModel m);
const char* toString(ResamplingScheme r);

}  // namespace tpf
}  // namespace picker_localisation
