#include "picker_localisation/sensors_vision/leg_pipeline.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "picker_localisation/core/yaml_file.h"
#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace vision {

const std::vector<std::string>& LegPipelineOptions::yamlKeys() {
  static const std::vector<std::string> keys = {"leg_threshold",
                                                "max_leg_range",
                                                "max_pair_distance",
                                                "single_leg_people",
                                                "jump_distance",
                                                "min_cluster_points",
                                                "gate_distance",
                                                "hits_to_confirm",
                                                "misses_to_delete",
                                                "tentative_misses",
                                                "promote_after",
                                                "demote_after",
                                                "camera_weight",
                                                "position_sigma",
                                                "require_confirmed",
                                                "max_fusion_cluster_width",
                                                "cone_half_width",
                                                "camera_fusion",
                                                "threshold_reference_increment",
                                                "negative_information",
                                                "negative_period",
                                                "negative_p_detect",
                                                "negative_range_full",
                                                "negative_range_max",
                                                "negative_clearance",
                                                "velocity_window"};
  return keys;
}

namespace {

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
  read(y, "velocity_window", o.tracker.velocity_window);
  read(y, "promote_after", o.fusion.promote_after);
  read(y, "demote_after", o.fusion.demote_after);
  read(y, "camera_weight", o.fusion.camera_weight);
  read(y, "position_sigma", o.position_sigma);
  read(y, "require_confirmed", o.require_confirmed);
  read(y, "max_fusion_cluster_width", o.max_fusion_cluster_width);
  read(y, "cone_half_width", o.cone_half_width);
  read(y, "negative_information", o.negative_information);
  read(y, "negative_period", o.negative_period);
  read(y, "negative_p_detect", o.negative_p_detect);
  read(y, "negative_range_full", o.negative_range_full);
  read(y, "negative_range_max", o.negative_range_max);
  read(y, "negative_clearance", o.negative_clearance);
  // The node enables fusion when a detections topic is set; the key may also be given explicitly.
  if (y["detections_topic"] && y["detections_topic"].IsScalar())
    o.camera_fusion = !y["detections_topic"].as<std::string>().empty();
  read(y, "camera_fusion", o.camera_fusion);
  const std::string problem = o.validate();
  if (!problem.empty()) throw std::runtime_error("leg_detector: " + problem);
  if (unknown)
    for (auto& m : core::unknownKeys(y, yamlKeys(), "leg_detector")) unknown->push_back(std::move(m));
  return o;
}

YAML::Node LegPipelineOptions::mergedSections(const std::vector<std::string>& files) {
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
  return merged;
}

LegPipelineOptions LegPipelineOptions::fromYamlFiles(const std::vector<std::string>& files,
                                                     std::vector<std::string>* unknown) {
  return fromYaml(mergedSections(files), unknown);
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
  // Bounded: a track keeps every scan of its window.
  if (!(tracker.velocity_window >= 0.0 && tracker.velocity_window <= 60.0))
    return bad("velocity_window", tracker.velocity_window, "in [0, 60] s (0: no velocity)");
  if (fusion.promote_after < 1) return bad("promote_after", fusion.promote_after, ">= 1");
  if (fusion.demote_after < 1) return bad("demote_after", fusion.demote_after, ">= 1");
  if (!(fusion.camera_weight > 0.0)) return bad("camera_weight", fusion.camera_weight, "> 0");
  if (!(position_sigma > 0.0) || !std::isfinite(position_sigma))
    return bad("position_sigma", position_sigma, "finite and > 0");
  if (!(max_fusion_cluster_width > 0.0))
    return bad("max_fusion_cluster_width", max_fusion_cluster_width, "> 0");
  if (!(cone_half_width > 0.0 && cone_half_width < M_PI))
    return bad("cone_half_width", cone_half_width, "in (0, pi)");
  if (!(negative_period >= 0.0) || !std::isfinite(negative_period))
    return bad("negative_period", negative_period, "finite and >= 0");
  if (!(negative_p_detect >= 0.0 && negative_p_detect < 1.0))
    return bad("negative_p_detect", negative_p_detect, "in [0, 1)");
  if (!(negative_range_full >= 0.0) || !std::isfinite(negative_range_full))
    return bad("negative_range_full", negative_range_full, "finite and >= 0");
  if (!(negative_range_max > negative_range_full) || !std::isfinite(negative_range_max))
    return bad("negative_range_max", negative_range_max, "finite and > negative_range_full");
  if (!(negative_clearance >= 0.0) || !std::isfinite(negative_clearance))
    return bad("negative_clearance", negative_clearance, "finite and >= 0");
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
  std::vector<std::optional<Eigen::Vector2d>> velocity_of(people.size());
  for (const auto& t : tracks)
    if (t.updated && t.detection >= 0) {
      track_of[t.detection] = t.id;
      confirmed[t.detection] = t.confirmed;
      if (t.has_window_velocity) velocity_of[t.detection] = t.window_velocity;
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
    t.velocity = velocity_of[i];
    out.push_back(std::move(t));
  }
  return out;
}

namespace {

// Whether the scan's beams towards `q` (sensor frame) reach at least `margin` beyond it: the nearest valid
// return of the beam and its two neighbours; a beam with no return within range_max (+inf, REP 117) sees to
// range_max; an invalid or too-close return (NaN, -inf) sees nothing.
bool seesThrough(const core::LaserScan& scan, const Eigen::Vector2d& q, double margin) {
  const double r = q.norm();
  if (!(r > scan.range_min) || r + margin > scan.range_max || !(scan.angle_increment > 0.0)) return false;
  const double a = std::atan2(q.y(), q.x());
  if (a < scan.angle_min || a > scan.angle_max) return false;
  const long k = std::lround((a - scan.angle_min) / scan.angle_increment);
  const long last = static_cast<long>(scan.ranges.size()) - 1;
  if (k < 0 || k > last) return false;
  for (long i = std::max(0L, k - 1); i <= std::min(last, k + 1); ++i) {
    const float v = scan.ranges[static_cast<std::size_t>(i)];
    if (std::isnan(v) || v < 0.0f) return false;  // invalid, or -inf: closer than range_min
    const double seen = std::isinf(v) || v > scan.range_max ? scan.range_max : static_cast<double>(v);
    if (seen < r + margin) return false;
  }
  return true;
}

}  // namespace

std::optional<core::Observation> LegPipeline::negativeObservation(
    const std::string& source_frame, double stamp, const core::LaserScan& scan,
    const Eigen::Isometry3d& fixed_from_sensor, const std::vector<PersonCandidate>& candidates,
    const topology::TopologicalMap& map, const std::string& robot_id) {
  const LegPipelineOptions& o = options_;
  if (!o.negative_information || !(o.negative_p_detect > 0.0) || !std::isfinite(stamp)) return std::nullopt;
  const auto last = last_negative_.find(source_frame);
  if (last != last_negative_.end() && stamp >= last->second && stamp - last->second < o.negative_period)
    return std::nullopt;
  // A node's cell: the half-edges to its neighbours (where a picker is nearer this node than that one) every
  // 0.25 m, each point also 0.5 m to either side (a lane is 1.3-1.5 m wide). The beams towards every point
  // must reach 0.3 m past it: a person standing anywhere in the cell, detected or not, blocks some of them.
  constexpr double kStep = 0.25, kSide = 0.5, kSeeBeyond = 0.3;
  std::vector<Eigen::Vector2d> people;
  for (const auto& c : candidates) people.push_back(c.position);
  const auto tracker = trackers_.find(source_frame);
  if (tracker != trackers_.end())
    for (const auto& t : tracker->second.tracks()) people.push_back(t.position);
  const Eigen::Isometry3d sensor_from_fixed = fixed_from_sensor.inverse();
  const Eigen::Vector2d origin = fixed_from_sensor.translation().head<2>();
  auto inSensor = [&](const Eigen::Vector2d& p) {
    return (sensor_from_fixed * Eigen::Vector3d(p.x(), p.y(), 0.0)).head<2>().eval();
  };
  core::Observation obs;
  core::setLikelihoodOverEveryNode(obs, map.numNodes());
  bool any = false;
  for (topology::NodeIndex n : map.nodesWithin(origin, o.negative_range_max)) {
    const Eigen::Vector2d p = map.position2d(n);
    const double r = (p - origin).norm();
    const double p_d =
        o.negative_p_detect *
        std::clamp((o.negative_range_max - r) / (o.negative_range_max - o.negative_range_full), 0.0, 1.0);
    if (!(p_d > 0.0)) continue;
    if (std::any_of(people.begin(), people.end(),
                    [&](const Eigen::Vector2d& q) { return (q - p).norm() < o.negative_clearance; }))
      continue;
    bool seen = true;
    auto look = [&](const Eigen::Vector2d& q) { seen = seen && seesThrough(scan, inSensor(q), kSeeBeyond); };
    const auto& neighbours = map.neighbours(n);
    for (topology::NodeIndex m : neighbours) {
      const Eigen::Vector2d d = map.position2d(m) - p;
      const double half = 0.5 * d.norm();
      if (!(half > 0.0)) continue;
      const Eigen::Vector2d u = d.normalized(), side(-u.y() * kSide, u.x() * kSide);
      for (double t = 0.0; seen && t <= half + 1e-9; t += kStep) {
        look(p + t * u);
        look(p + t * u + side);
        look(p + t * u - side);
      }
    }
    if (neighbours.empty())
      for (const Eigen::Vector2d& d :
           {Eigen::Vector2d(0, 0), Eigen::Vector2d(kSide, 0), Eigen::Vector2d(-kSide, 0),
            Eigen::Vector2d(0, kSide), Eigen::Vector2d(0, -kSide)})
        look(p + d);
    if (!seen) continue;
    obs.likelihood[n] = 1.0 - p_d;
    any = true;
  }
  if (!any) return std::nullopt;
  last_negative_[source_frame] = stamp;
  obs.stamp = stamp;
  obs.sensor = "lidar";
  obs.robot_id = robot_id;
  obs.identifying = false;
  return obs;
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
  obs.velocity = person.velocity;
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
