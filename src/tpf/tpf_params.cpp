#include "picker_localisation/tpf/tpf_params.h"

#include "picker_localisation/core/yaml_file.h"
#include "picker_localisation/core/yaml_keys.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace picker_localisation {
namespace tpf {

TpfParams::TpfParams() {
  // Table I: gamma^GPS = (1, 1), gamma^LIDAR = (0.25, 0), gamma^RFID = (1, 0).
  sensor_gammas["gnss"] = SensorGamma{1.0, 1.0};
  sensor_gammas["lidar"] = SensorGamma{0.25, 0.0};
  sensor_gammas["rfid"] = SensorGamma{1.0, 0.0};
  // Not in the paper: UWB identifies like RFID; a camera is anonymous like LiDAR.
  sensor_gammas["uwb"] = SensorGamma{1.0, 0.0};
  sensor_gammas["camera"] = SensorGamma{0.25, 0.0};
  // Not in the paper: map-frame picker positions (gnss_ingest ~pose_topic_format, e.g. a phone app's server),
  // trusted as GNSS; other people detectors' anonymous poses (~people_pose_topics) as LiDAR.
  sensor_gammas["pose"] = SensorGamma{1.0, 0.0};
  sensor_gammas["people"] = SensorGamma{0.25, 0.0};
  // Not RFID: its read region is a ring, not a position (tpf_params.h).
  reinit_sensors = {"gnss", "uwb", "pose"};
}

SensorGamma TpfParams::gammaFor(const std::string& sensor) const {
  auto it = sensor_gammas.find(sensor);
  return it == sensor_gammas.end() ? default_gamma : it->second;
}

bool TpfParams::acceptsSensor(const std::string& sensor) const {
  return accepted_sensors.empty() ||
         std::find(accepted_sensors.begin(), accepted_sensors.end(), sensor) != accepted_sensors.end();
}

bool TpfParams::usesBiasState(const std::string& sensor) const {
  return gnss_bias_state &&
         std::find(gnss_bias_sensors.begin(), gnss_bias_sensors.end(), sensor) != gnss_bias_sensors.end();
}

bool TpfParams::isLaneEvidence(const std::string& sensor) const {
  return std::find(lane_evidence_sensors.begin(), lane_evidence_sensors.end(), sensor) !=
         lane_evidence_sensors.end();
}

std::string TpfParams::validate() const {
  auto finite_nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (num_particles == 0 || num_particles > kMaxParticles)
    return core::badValue("num_particles", static_cast<double>(num_particles), "in [1, 100000]");
  if (!std::isfinite(velocity_init_mean) || !finite_nonneg(velocity_init_variance))
    return "velocity_init_mean / velocity_init_variance must be finite, variance >= 0";
  if (!std::isfinite(velocity_noise_mean) || !finite_nonneg(velocity_noise_variance))
    return "velocity_noise_mean / velocity_noise_variance must be finite, variance >= 0";
  if (!finite_nonneg(dwell_init_min) || !std::isfinite(dwell_init_max) || dwell_init_max < dwell_init_min)
    return core::badValue("dwell_init_min", dwell_init_min, ">= 0 and <= dwell_init_max");
  if (!std::isfinite(dwell_noise_min) || !std::isfinite(dwell_noise_max) || dwell_noise_max < dwell_noise_min)
    return core::badValue("dwell_noise_min", dwell_noise_min, "<= dwell_noise_max");
  if (!finite_nonneg(fixed_lambda)) return core::badValue("fixed_lambda", fixed_lambda, ">= 0");
  if (!(velocity_window >= 1.0) || !std::isfinite(velocity_window))
    return core::badValue("velocity_window", velocity_window, ">= 1");
  if (!(reinit_fraction > 0.0 && reinit_fraction <= 1.0))
    return core::badValue("reinit_fraction", reinit_fraction, "in (0, 1]");
  if (!(lane_change_leak >= 0.0 && lane_change_leak <= 1.0))
    return core::badValue("lane_change_leak", lane_change_leak, "in [0, 1]");
  if (lane_change_max_hops < 1 || lane_change_max_hops > kMaxLaneChangeHops)
    return core::badValue("lane_change_max_hops", static_cast<double>(lane_change_max_hops), "in [1, 50]");
  if (!(lane_change_keep_side >= 0.0 && lane_change_keep_side <= 1.0))
    return core::badValue("lane_change_keep_side", lane_change_keep_side, "in [0, 1]");
  if (!(reverse_rate >= 0.0) || !std::isfinite(reverse_rate))
    return core::badValue("reverse_rate", reverse_rate, "finite and >= 0");
  if (!(stand_rate >= 0.0) || !std::isfinite(stand_rate))
    return core::badValue("stand_rate", stand_rate, "finite and >= 0");
  if (!(walk_rate > 0.0) || !std::isfinite(walk_rate))
    return core::badValue("walk_rate", walk_rate, "finite and > 0");
  if (!(anonymous_min_support >= 0.0 && anonymous_min_support <= 1.0))
    return core::badValue("anonymous_min_support", anonymous_min_support, "in [0, 1]");
  if (!(turn_projection_fraction >= 0.0 && turn_projection_fraction <= 1.0))
    return core::badValue("turn_projection_fraction", turn_projection_fraction, "in [0, 1]");
  if (!(min_jump_dwell > 0.0) || !std::isfinite(min_jump_dwell))
    return core::badValue("min_jump_dwell", min_jump_dwell, "> 0");
  if (!(min_velocity_sigma > 0.0) || !std::isfinite(min_velocity_sigma))
    return core::badValue("min_velocity_sigma", min_velocity_sigma, "> 0");
  for (const auto& [name, g] : sensor_gammas)
    if (!finite_nonneg(g.node) || !finite_nonneg(g.velocity))
      return "sensor_gammas." + name + " must be finite and >= 0";
  if (!finite_nonneg(default_gamma.node) || !finite_nonneg(default_gamma.velocity))
    return "default_gamma must be finite and >= 0";
  if (!(jsd_threshold >= 0.0 && jsd_threshold <= 1.0))
    return core::badValue("jsd_threshold", jsd_threshold, "in [0, 1]");
  if (!(reinit_max_mean_likelihood > 0.0 && reinit_max_mean_likelihood <= 1.0))
    return core::badValue("reinit_max_mean_likelihood", reinit_max_mean_likelihood, "in (0, 1]");
  if (!finite_nonneg(entropy_threshold))
    return core::badValue("entropy_threshold", entropy_threshold, ">= 0");
  if (!(unconnected_jump_probability >= 0.0 && unconnected_jump_probability <= 1.0))
    return core::badValue("unconnected_jump_probability", unconnected_jump_probability, "in [0, 1]");
  if (!(prediction_rate >= 0.0 && prediction_rate <= kMaxPredictionRate))
    return core::badValue("prediction_rate", prediction_rate, "in [0, 10] Hz");
  if (!finite_nonneg(reorder_window)) return core::badValue("reorder_window", reorder_window, ">= 0");
  if (!(gnss_bias_fix_std > 0.0) || !std::isfinite(gnss_bias_fix_std))
    return core::badValue("gnss_bias_fix_std", gnss_bias_fix_std, "finite and > 0");
  if (!(lane_swap_rate >= 0.0 && lane_swap_rate <= 1.0))
    return core::badValue("lane_swap_rate", lane_swap_rate, "in [0, 1] per s");
  if (!(lane_swap_max_distance > 0.0 && lane_swap_max_distance <= 20.0))
    return core::badValue("lane_swap_max_distance", lane_swap_max_distance, "in (0, 20] m");
  if (!(lane_swap_memory > 0.0 && lane_swap_memory <= 86400.0))
    return core::badValue("lane_swap_memory", lane_swap_memory, "in (0, 86400] s");
  if (lane_evidence_sweeps < 0 || lane_evidence_sweeps > 50)
    return core::badValue("lane_evidence_sweeps", lane_evidence_sweeps, "in [0, 50]");
  return "";
}

namespace {

template <typename T>
void read(const YAML::Node& node, const char* key, T& value) {
  const YAML::Node v = node[key];
  if (!v) return;
  try {
    value = v.as<T>();
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("tpf params: bad value for '") + key + "': " + e.what());
  }
}

// A string key naming one of `choices`.
template <typename E>
void readChoice(const YAML::Node& node, const char* key,
                const std::vector<std::pair<std::string, E>>& choices, E& value) {
  std::string name;
  read(node, key, name);
  if (name.empty()) return;
  std::string known;
  for (const auto& [n, v] : choices) {
    if (n == name) {
      value = v;
      return;
    }
    known += (known.empty() ? "" : " | ") + n;
  }
  throw std::runtime_error(std::string("tpf params: '") + key + "' must be " + known + ", got '" + name +
                           "'");
}

SensorGamma readGamma(const YAML::Node& node, const std::string& key) {
  SensorGamma g;
  if (!node.IsMap())
    throw std::runtime_error("tpf params: '" + key + "' must be a map {node: .., velocity: ..}");
  read(node, "node", g.node);
  read(node, "velocity", g.velocity);
  return g;
}

}  // namespace

const std::vector<std::string>& TpfParams::yamlKeys() {
  static const std::vector<std::string> keys = {"num_particles",
                                                "velocity_init_mean",
                                                "velocity_init_variance",
                                                "dwell_init_min",
                                                "dwell_init_max",
                                                "velocity_noise_mean",
                                                "velocity_noise_variance",
                                                "dwell_noise_min",
                                                "dwell_noise_max",
                                                "fixed_lambda",
                                                "velocity_window",
                                                "min_jump_dwell",
                                                "directed_motion",
                                                "turn_projection_fraction",
                                                "min_velocity_sigma",
                                                "velocity_weight_product",
                                                "velocity_follows_edge",
                                                "reverse_rate",
                                                "stand_rate",
                                                "walk_rate",
                                                "anonymous_min_support",
                                                "weigh_anonymous_by_association",
                                                "weigh_named_by_association",
                                                "lane_change_model",
                                                "lane_change_leak",
                                                "lane_change_max_hops",
                                                "lane_change_keep_side",
                                                "accepted_sensors",
                                                "jsd_monitor",
                                                "jsd_threshold",
                                                "reinit_max_mean_likelihood",
                                                "reinit_fraction",
                                                "reinit_sensors",
                                                "entropy_gate",
                                                "entropy_threshold",
                                                "unconnected_jump_probability",
                                                "prediction_rate",
                                                "reorder_window",
                                                "gnss_bias_state",
                                                "gnss_bias_sensors",
                                                "gnss_bias_fix_std",
                                                "lane_swap_rate",
                                                "lane_swap_max_distance",
                                                "lane_swap_memory",
                                                "lane_evidence_sensors",
                                                "lane_evidence_sweeps",
                                                "lane_evidence_projection",
                                                "map_node_by_lane",
                                                "lane_masses_by_swap_prior",
                                                "resampling",
                                                "motion_model",
                                                "sensor_gammas",
                                                "default_gamma",
                                                "method"};
  return keys;
}

TpfParams TpfParams::fromYaml(const YAML::Node& node, std::vector<std::string>* unknown) {
  TpfParams p;
  if (!node || node.IsNull()) return p;
  if (!node.IsMap()) throw std::runtime_error("tpf params: top level must be a map");

  std::size_t particles = p.num_particles;
  read(node, "num_particles", particles);
  p.num_particles = particles;
  readChoice(
      node, "resampling",
      {{"low_variance", ResamplingScheme::kLowVariance}, {"multinomial", ResamplingScheme::kMultinomial}},
      p.resampling);
  read(node, "velocity_init_mean", p.velocity_init_mean);
  read(node, "velocity_init_variance", p.velocity_init_variance);
  read(node, "dwell_init_min", p.dwell_init_min);
  read(node, "dwell_init_max", p.dwell_init_max);
  read(node, "velocity_noise_mean", p.velocity_noise_mean);
  read(node, "velocity_noise_variance", p.velocity_noise_variance);
  read(node, "dwell_noise_min", p.dwell_noise_min);
  read(node, "dwell_noise_max", p.dwell_noise_max);
  readChoice(node, "motion_model",
             {{"velocity", MotionModel::kVelocity}, {"fixed_lambda", MotionModel::kFixedLambda}},
             p.motion_model);
  read(node, "fixed_lambda", p.fixed_lambda);
  read(node, "velocity_window", p.velocity_window);
  read(node, "min_jump_dwell", p.min_jump_dwell);
  read(node, "directed_motion", p.directed_motion);
  read(node, "turn_projection_fraction", p.turn_projection_fraction);
  if (const YAML::Node g = node["sensor_gammas"]) {
    if (!g.IsMap()) throw std::runtime_error("tpf params: 'sensor_gammas' must be a map");
    for (const auto& kv : g) {
      const std::string name = kv.first.as<std::string>();
      p.sensor_gammas[name] = readGamma(kv.second, "sensor_gammas." + name);
    }
  }
  if (const YAML::Node g = node["default_gamma"]) p.default_gamma = readGamma(g, "default_gamma");
  read(node, "min_velocity_sigma", p.min_velocity_sigma);
  read(node, "velocity_weight_product", p.velocity_weight_product);
  read(node, "velocity_follows_edge", p.velocity_follows_edge);
  read(node, "reverse_rate", p.reverse_rate);
  read(node, "stand_rate", p.stand_rate);
  read(node, "walk_rate", p.walk_rate);
  read(node, "anonymous_min_support", p.anonymous_min_support);
  read(node, "weigh_anonymous_by_association", p.weigh_anonymous_by_association);
  read(node, "weigh_named_by_association", p.weigh_named_by_association);
  read(node, "lane_change_model", p.lane_change_model);
  read(node, "lane_change_leak", p.lane_change_leak);
  read(node, "lane_change_max_hops", p.lane_change_max_hops);
  read(node, "lane_change_keep_side", p.lane_change_keep_side);
  read(node, "accepted_sensors", p.accepted_sensors);
  read(node, "jsd_monitor", p.jsd_monitor);
  read(node, "jsd_threshold", p.jsd_threshold);
  read(node, "reinit_max_mean_likelihood", p.reinit_max_mean_likelihood);
  read(node, "reinit_fraction", p.reinit_fraction);
  read(node, "reinit_sensors", p.reinit_sensors);
  read(node, "entropy_gate", p.entropy_gate);
  read(node, "entropy_threshold", p.entropy_threshold);
  read(node, "unconnected_jump_probability", p.unconnected_jump_probability);
  read(node, "prediction_rate", p.prediction_rate);
  read(node, "reorder_window", p.reorder_window);
  read(node, "gnss_bias_state", p.gnss_bias_state);
  read(node, "gnss_bias_sensors", p.gnss_bias_sensors);
  read(node, "gnss_bias_fix_std", p.gnss_bias_fix_std);
  read(node, "lane_swap_rate", p.lane_swap_rate);
  read(node, "lane_swap_max_distance", p.lane_swap_max_distance);
  read(node, "lane_swap_memory", p.lane_swap_memory);
  read(node, "lane_evidence_sensors", p.lane_evidence_sensors);
  read(node, "lane_evidence_sweeps", p.lane_evidence_sweeps);
  read(node, "lane_evidence_projection", p.lane_evidence_projection);
  read(node, "map_node_by_lane", p.map_node_by_lane);
  read(node, "lane_masses_by_swap_prior", p.lane_masses_by_swap_prior);
  if (node["method"]) {  // mode switches win
    try {
      p = presetForMethod(node["method"].as<std::string>(), p);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(std::string("tpf params: 'method': ") + e.what());
    }
  }
  const std::string problem = p.validate();
  if (!problem.empty()) throw std::runtime_error("tpf params: " + problem);
  if (unknown)
    for (auto& m : core::unknownKeys(node, yamlKeys(), "tpf params")) unknown->push_back(std::move(m));
  return p;
}

TpfParams TpfParams::fromYamlFile(const std::string& path, std::vector<std::string>* unknown) {
  return core::parseYamlFile(path, [unknown](const YAML::Node& root) { return fromYaml(root, unknown); });
}

std::vector<std::string> TpfParams::methodNames() {
  return {"tpf", "paper_tpf", "khan_connected", "khan_unconnected", "no_monitor", "constant_speed"};
}

TpfParams TpfParams::presetForMethod(const std::string& method, const TpfParams& base) {
  TpfParams p = base;
  if (method == "tpf") return p;
  if (method == "paper_tpf") {
    // Navigate-and-Seek's filter read literally: Eq. 7 blends the velocity vector, Eq. 8 adds the velocity
    // term, particles turn only at lane ends, no lane-change structure, Algorithm 1's JSD re-initialisation.
    p.velocity_follows_edge = false;
    p.velocity_weight_product = false;
    p.reverse_rate = 0.0;
    p.stand_rate = 0.0;
    p.anonymous_min_support = 0.0;
    p.weigh_anonymous_by_association = false;
    p.weigh_named_by_association = false;
    p.lane_evidence_projection = false;
    p.lane_change_model = false;
    p.jsd_monitor = true;
    p.reinit_fraction = 1.0;
    p.reinit_sensors.clear();
    p.gnss_bias_state = false;
    p.map_node_by_lane = false;
    return p;
  }
  if (method == "khan_connected" || method == "khan_unconnected") {
    // Khan et al. [1]: GNSS only, fixed lambda 0.1, no monitors; "unconnected" lets a small share of the
    // particles jump anywhere at every resampling (fixed p_rj), "connected" never.
    p.motion_model = MotionModel::kFixedLambda;
    p.fixed_lambda = 0.1;
    p.accepted_sensors = {"gnss"};
    p.jsd_monitor = false;
    p.entropy_gate = false;
    p.gnss_bias_state = false;  // each fix independent, as in [1]
    p.map_node_by_lane = false;  // Eq. 10 as written
    if (method == "khan_connected")
      p.unconnected_jump_probability = 0.0;
    else if (p.unconnected_jump_probability <= 0.0)
      p.unconnected_jump_probability = 1e-3;
    return p;
  }
  if (method == "no_monitor") {
    // Stripped of both mechanisms of Sec. IV: no JSD re-initialisation and no (entropy-gated) jumps to
    // unconnected nodes.
    p.jsd_monitor = false;
    p.entropy_gate = false;
    p.unconnected_jump_probability = 0.0;
    return p;
  }
  if (method == "constant_speed") {
    // "does not estimate the particles velocity but uses a constant value, similar to [1]".
    p.motion_model = MotionModel::kFixedLambda;
    p.fixed_lambda = 0.1;
    return p;
  }
  std::ostringstream names;
  for (const auto& n : methodNames()) names << ' ' << n;
  throw std::invalid_argument("unknown TPF method '" + method + "' (known:" + names.str() + ")");
}

const char* toString(MotionModel m) {
  return m == MotionModel::kVelocity ? "velocity" : "fixed_lambda";
}
const char* toString(ResamplingScheme r) {
  return r == ResamplingScheme::kLowVariance ? "low_variance" : "multinomial";
}

}  // namespace tpf
}  // namespace picker_localisation
