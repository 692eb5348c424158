#include "picker_localisation/sensors_vision/leg_pipeline.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "picker_localisation/core/yaml_file.h"
#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace vision {

namespace {

// Keys the leg_detector node reads itself (topics, frames, model, timeouts): valid here, not used here.
const std::vector<std::string>& nodeOnlyKeys() {
  static const std::vector<std::string> keys = {
      "scan_topics",          "cloud_topic",        "detections_topic", "camera_info_topic", "model_file",
      "fixed_frame",          "robot_id",           "tf_timeout",       "map_file",          "map_timeout",
      "publish_observations", "observations_topic", "fusion_max_age",   "map_topic", "max_future_stamp",
      "max_beams"};
  return keys;
}
const std::vector<std::string>& pipelineKeys() {
  static const std::vector<std::string> keys = {
      "leg_threshold",    "max_leg_range",      "max_pair_distance", "single_leg_people",
      "jump_distance",    "min_cluster_points", "gate_distance",     "hits_to_confirm",
      "misses_to_delete", "tentative_misses",   "promote_after",     "demote_after",
      "camera_weight",    "position_sigma",     "require_confirmed", "max_fusion_cluster_width",
      "cone_half_width",  "camera_fusion",      "threshold_reference_increment"};
  return keys;
}

template <typename T>
void read(const YAML::Node& y, const char* key, T& value) {
  if (!y[key]) return;
  try {
    value = y[key].as<T>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(std::string("leg_detector: key '") + key + "' has the wrong type");
  }
}

}  // namespace

LegPipelineOptions LegPipelineOptions::fromYaml(const YAML::Node& y, std::vector<std::string>* unknown) {
  LegPipelineOptions o;
  if (!y || !y.IsMap()) return o;
  read(y, "leg_threshold", o.detector.leg_threshold);
  read(y, "threshold_reference_increment", o.detector.threshold_reference_increment);
  read(y, "max_leg_range", o.detector.max_leg_range);
  read(y, "max_pair_distance", o.detector.max_pair_distance);
  read(y, "single_leg_people", o.detector.single_leg_people);
  read(y, "jump_distance", o.detector.segmentation.jump_distance);
  int min_points = static_cast<int>(o.detector.segmentation.min_points);
  read(y, "min_cluster_points", min_points);
  if (min_points < 1)
    throw std::runtime_error("leg_detector: min_cluster_points = " + std::to_string(min_points) +
                             ": must be >= 1");
  o.detector.segmentation.min_points = static_cast<std::size_t>(min_points);
  read(y, "gate_distance", o.tracker.gate_distance);
  read(y, "hits_to_confirm", o.tracker.hits_to_confirm);
  read(y, "misses_to_delete", o.tracker.misses_to_delete);
  read(y, "tentative_misses", o.tracker.tentative_misses);
  read(y, "promote_after", o.fusion.promote_after);
  read(y, "demote_after", o.fusion.demote_after);
  read(y, "camera_weight", o.fusion.camera_weight);
  read(y, "position_sigma", o.position_sigma);
  read(y, "require_confirmed", o.require_confirmed);
  read(y, "max_fusion_cluster_width", o.max_fusion_cluster_width);
  read(y, "cone_half_width", o.cone_half_width);
  // The node enables fusion when a detections topic is set; the key may also be given explicitly.
  if (y["detections_topic"] && y["detections_topic"].IsScalar())
    o.camera_fusion = !y["detections_topic"].as<std::string>().empty();
  read(y, "camera_fusion", o.camera_fusion);
  const std::string problem = o.validate();
  if (!problem.empty()) throw std::runtime_error("leg_detector: " + problem);
  if (unknown) {
    std::vector<std::string> known = pipelineKeys();
    known.insert(known.end(), nodeOnlyKeys().begin(), nodeOnlyKeys().end());
    for (auto& m : core::unknownKeys(y, known, "leg_detector")) unknown->push_back(std::move(m));
  }
  return o;
}

LegPipelineOptions LegPipelineOptions::fromYamlFiles(const std::vector<std::string>& files,
                                                     std::vector<std::string>* unknown) {
  // Merge the sections key by key (later files win), then parse once.
  YAML::Node merged(YAML::NodeType::Map);
  for (const auto& f : files) {
    core::parseYamlFile(f, [&](const YAML::Node& root) {
      const YAML::Node s = root["leg_detector"];
      if (s && s.IsMap())
        for (const auto& kv : s) merged[kv.first.as<std::string>()] = kv.second;
      return 0;
    });
  }
  return fromYaml(merged, unknown);
}

std::string LegPipelineOptions::validate() const {
  std::ostringstream s;
  auto bad = [&](const char* key, double v, const char* rule) {
    s << key << " = " << v << ": must be " << rule;
    return s.str();
  };
  const auto& d = detector;
  if (!(d.leg_threshold >= 0.0 && d.leg_threshold <= 1.0))
    return bad("leg_threshold", d.leg_threshold, "in [0, 1]");
  if (!(d.threshold_reference_increment >= 0.0 && d.threshold_reference_increment < 0.5))
    return bad("threshold_reference_increment", d.threshold_reference_increment,
               "in [0, 0.5) rad (0: no scaling)");
  if (!(d.max_leg_range > 0.0)) return bad("max_leg_range", d.max_leg_range, "> 0");
  if (!(d.max_pair_distance > 0.0)) return bad("max_pair_distance", d.max_pair_distance, "> 0");
  if (!(d.segmentation.jump_distance > 0.0)) return bad("jump_distance", d.segmentation.jump_distance, "> 0");
  if (!(tracker.gate_distance > 0.0)) return bad("gate_distance", tracker.gate_distance, "> 0");
  if (tracker.hits_to_confirm < 1) return bad("hits_to_confirm", tracker.hits_to_confirm, ">= 1");
  if (tracker.misses_to_delete < 1) return bad("misses_to_delete", tracker.misses_to_delete, ">= 1");
  if (tracker.tentative_misses < 1) return bad("tentative_misses", tracker.tentative_misses, ">= 1");
  if (fusion.promote_after < 1) return bad("promote_after", fusion.promote_after, ">= 1");
  if (fusion.demote_after < 1) return bad("demote_after", fusion.demote_after, ">= 1");
  if (!(fusion.camera_weight > 0.0)) return bad("camera_weight", fusion.camera_weight, "> 0");
  if (!(position_sigma > 0.0) || !std::isfinite(position_sigma))
    return bad("position_sigma", position_sigma, "finite and > 0");
  if (!(max_fusion_cluster_width > 0.0))
    return bad("max_fusion_cluster_width", max_fusion_cluster_width, "> 0");
  if (!(cone_half_width > 0.0 && cone_half_width < M_PI))
    return bad("cone_half_width", cone_half_width, "in (0, pi)");
  return "";
}

LegPipeline::LegPipeline(std::shared_ptr<const LegClassifier> classifier, LegPipelineOptions options)
    : options_(std::move(options)),
      detector_(std::move(classifier), options_.detector),
      fusion_(options_.fusion) {
  const std::string problem = options_.validate();
  if (!problem.empty()) throw std::invalid_argument("LegPipeline: " + problem);
}

std::vector<PersonCandidate> LegPipeline::scanCandidates(const core::LaserScan& scan,
                                                         const Eigen::Isometry3d& fixed_from_sensor) const {
  const LegDetection detection = detector_.detect(scan);
  auto toFixed = [&](const Eigen::Vector2d& p) {
    return (fixed_from_sensor * Eigen::Vector3d(p.x(), p.y(), 0.0)).head<2>().eval();
  };
  std::vector<PersonCandidate> people;
  for (const auto& p : detection.people) people.push_back({toFixed(p.position), p.confidence, "lidar", true});
  if (options_.camera_fusion) {
    // Every other cluster of person size is a fusion candidate too: a camera cone may promote it.
    std::vector<char> used(detection.clusters.size(), 0);
    for (const auto& p : detection.people) {
      if (p.leg_a >= 0) used[detection.legs[p.leg_a].cluster_index] = 1;
      if (p.leg_b >= 0) used[detection.legs[p.leg_b].cluster_index] = 1;
    }
    for (std::size_t i = 0; i < detection.clusters.size(); ++i) {
      const auto& c = detection.clusters[i];
      if (used[i] || (c.points.back() - c.points.front()).norm() > options_.max_fusion_cluster_width)
        continue;
      people.push_back({toFixed(c.centroid()), 0.0, "lidar", false});
    }
  }
  return people;
}

std::vector<TrackedPerson> LegPipeline::track(const std::string& source_frame, double stamp,
                                              const std::vector<PersonCandidate>& people,
                                              const CameraCones* camera) {
  std::vector<Eigen::Vector2d> positions;
  for (const auto& p : people) positions.push_back(p.position);
  auto tracker = trackers_.find(source_frame);
  if (tracker == trackers_.end()) {
    // One tracker per sensor frame, ids kept disjoint (first_id = k * 1000000).
    auto o = options_.tracker;
    o.first_id = static_cast<int>(trackers_.size()) * 1000000;
    tracker = trackers_.emplace(source_frame, ClusterTracker(o)).first;
  }
  const auto& tracks = tracker->second.update(stamp, positions);
  std::vector<int> track_of(people.size(), -1);
  std::vector<bool> confirmed(people.size(), false);
  for (const auto& t : tracks)
    if (t.updated && t.detection >= 0) {
      track_of[t.detection] = t.id;
      confirmed[t.detection] = t.confirmed;
    }
  // Camera fusion (Algorithm 4): the candidates in the camera's horizontal frame, one cone per box.
  std::vector<FusionCandidate> candidates;
  for (std::size_t i = 0; i < people.size(); ++i) {
    Eigen::Vector2d q = people[i].position;
    if (camera) q = (camera->camera_from_fixed * Eigen::Vector3d(q.x(), q.y(), 0.0)).head<2>();
    candidates.push_back({q, track_of[i], people[i].confidence});
  }
  const std::vector<FusedPerson> fused =
      camera ? fusion_.fuse(candidates, camera->cones, true) : fusion_.fuse(candidates, {}, false);

  std::vector<TrackedPerson> out;
  const double var = options_.position_sigma * options_.position_sigma;
  for (std::size_t i = 0; i < people.size(); ++i) {
    const bool cam = fused[i].camera_confirmed;
    if (!people[i].classified && !cam) continue;                        // plain cluster, no cone
    if (options_.require_confirmed && !confirmed[i] && !cam) continue;  // hysteresis: spurious clusters out
    TrackedPerson t;
    t.position = people[i].position;
    t.variance = cam ? 0.5 * var : var;  // camera-confirmed people are weighted higher
    t.sensor = cam ? people[i].sensor + "_camera" : people[i].sensor;
    t.confidence = fused[i].confidence;
    t.track_id = track_of[i];
    t.camera_confirmed = cam;
    camera_confirmed_ += cam ? 1 : 0;
    out.push_back(std::move(t));
  }
  return out;
}

core::Observation LegPipeline::observation(const TrackedPerson& person, const topology::TopologicalMap& map,
                                           double stamp, const std::string& robot_id) {
  core::Observation obs;
  obs.stamp = stamp;
  obs.sensor = "lidar";
  obs.robot_id = robot_id;
  obs.identifying = false;
  obs.position = person.position;
  obs.position_covariance = Eigen::Matrix2d::Identity() * person.variance;
  core::setGaussianLikelihood(obs, map, person.position, obs.position_covariance);
  return obs;
}

std::size_t LegPipeline::liveTracks() const {
  std::size_t live = 0;
  for (const auto& t : trackers_) live += t.second.tracks().size();
  return live;
}

}  // namespace vision
}  // namespace picker_localisation
