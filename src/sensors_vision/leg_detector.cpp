#include "picker_localisation/sensors_vision/leg_detector.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

namespace picker_localisation {
namespace vision {

bool isLegCandidate(const ScanCluster& cluster, const LegDetectorOptions& options) {
  if (cluster.points.empty()) return false;
  return cluster.centroid().norm() <= options.max_leg_range &&
         (cluster.points.back() - cluster.points.front()).norm() <= options.max_leg_width;
}

double thresholdFor(const LegDetectorOptions& options, double angle_increment) {
  const double increment = std::abs(angle_increment);
  if (!(options.threshold_reference_increment > 0.0) || !(increment > options.threshold_reference_increment))
    return options.leg_threshold;
  return options.leg_threshold * options.threshold_reference_increment / increment;
}

std::vector<Person> pairLegs(const std::vector<Leg>& legs, const LegDetectorOptions& options) {
  std::vector<std::tuple<double, int, int>> pairs;
  for (std::size_t a = 0; a < legs.size(); ++a)
    for (std::size_t b = a + 1; b < legs.size(); ++b) {
      const double d = (legs[a].position - legs[b].position).norm();
      if (d < options.max_pair_distance) pairs.emplace_back(d, static_cast<int>(a), static_cast<int>(b));
    }
  std::sort(pairs.begin(), pairs.end());
  std::vector<char> used(legs.size(), 0);
  std::vector<Person> people;
  for (const auto& [d, a, b] : pairs) {
    if (used[a] || used[b]) continue;
    used[a] = used[b] = 1;
    Person p;
    p.position = 0.5 * (legs[a].position + legs[b].position);
    p.confidence = 0.5 * (legs[a].confidence + legs[b].confidence);
    p.leg_a = a;
    p.leg_b = b;
    people.push_back(p);
  }
  if (options.single_leg_people)
    for (std::size_t a = 0; a < legs.size(); ++a) {
      if (used[a]) continue;
      Person p;
      p.position = legs[a].position;
      p.confidence = legs[a].confidence * options.single_leg_factor;
      p.leg_a = static_cast<int>(a);
      people.push_back(p);
    }
  return people;
}

LegDetector::LegDetector(std::shared_ptr<const LegClassifier> classifier, LegDetectorOptions options)
    : classifier_(std::move(classifier)), options_(options) {
  if (!classifier_ || !classifier_->trained()) throw std::invalid_argument("LegDetector: needs a trained classifier");
}

LegDetection LegDetector::detect(const core::LaserScan& scan) const {
  LegDetection out;
  out.stamp = scan.stamp;
  out.clusters = segmentScan(scan, options_.segmentation);
  std::vector<LegFeatures> features;
  std::vector<std::size_t> candidates;
  for (std::size_t i = 0; i < out.clusters.size(); ++i) {
    if (!isLegCandidate(out.clusters[i], options_)) continue;
    features.push_back(LegFeatures::compute(out.clusters[i], &scan));
    candidates.push_back(i);
  }
  const auto prob = classifier_->legProbability(features);
  const double threshold = thresholdFor(options_, scan.angle_increment);
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if (prob[k] < threshold) continue;
    Leg leg;
    leg.position = out.clusters[candidates[k]].centroid();
    leg.confidence = prob[k];
    leg.cluster_index = candidates[k];
    out.legs.push_back(leg);
  }
  out.people = pairLegs(out.legs, options_);
  return out;
}

}  // namespace vision
}  // namespace picker_localisation
