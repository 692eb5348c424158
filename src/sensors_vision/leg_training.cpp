#include "picker_localisation/sensors_vision/leg_training.h"

#include <algorithm>
#include <limits>

#include "picker_localisation/sensors_vision/munkres.h"

namespace picker_localisation {
namespace vision {
void collectTrainingSamples(const std::vector<LabelledScan>& positives, const std::vector<core::LaserScan>& negatives,
                            const LegDetectorOptions& options, double match_distance, double unlabelled_negative_distance,
                            std::vector<LegFeatures>& samples, std::vector<int>& labels) {
  for (const auto& ls : positives) {
    for (const auto& c : segmentScan(ls.scan, options.segmentation)) {
      if (!isLegCandidate(c, options)) continue;
      const auto f = LegFeatures::compute(c, &ls.scan);
      const Eigen::Vector2d centre = c.centroid();
      double nearest = std::numeric_limits<double>::infinity();
      for (const auto& l : ls.legs) nearest = std::min(nearest, (l - centre).norm());
      if (nearest < match_distance) {
        samples.push_back(f);
        labels.push_back(1);
      } else if (unlabelled_negative_distance > 0.0 && nearest > unlabelled_negative_distance) {
        samples.push_back(f);
        labels.push_back(0);
      }
    }
  }
  for (const auto& scan : negatives)
    for (const auto& c : segmentScan(scan, options.segmentation)) {
      if (!isLegCandidate(c, options)) continue;
      samples.push_back(LegFeatures::compute(c, &scan));
      labels.push_back(0);
    }
}

LegEvaluation evaluateLegs(const LegDetector& detector, const std::vector<LabelledScan>& scans, double hit_distance) {
  LegEvaluation e;
  for (const auto& ls : scans) {
    const auto det = detector.detect(ls.scan);
    ++e.scans;
    e.labels += ls.legs.size();
    e.detections += det.legs.size();
    Eigen::MatrixXd cost(static_cast<long>(ls.legs.size()), static_cast<long>(det.legs.size()));
    for (std::size_t i = 0; i < ls.legs.size(); ++i)
      for (std::size_t j = 0; j < det.legs.size(); ++j)
        cost(static_cast<long>(i), static_cast<long>(j)) = (ls.legs[i] - det.legs[j].position).norm();
    const auto assign = solveAssignment(cost);
    for (std::size_t i = 0; i < assign.size(); ++i)
      if (assign[i] >= 0 && cost(static_cast<long>(i), assign[i]) <= hit_distance) ++e.true_positives;
  }
  return e;
}

LegEvaluation evaluateNegatives(const LegDetector& detector, const std::vector<core::LaserScan>& scans) {
  LegEvaluation e;
  for (const auto& scan : scans) {
    ++e.scans;
    e.detections += detector.detect(scan).legs.size();
  }
  return e;
}

std::vector<LegCurvePoint> legCurve(std::shared_ptr<const LegClassifier> classifier,
                                    LegDetectorOptions options, const std::vector<LabelledScan>& labelled,
                                    const std::vector<core::LaserScan>& negatives,
                                    const std::vector<core::LaserScan>& other,
                                    const std::vector<double>& thresholds, double hit_distance) {
  std::vector<LegCurvePoint> curve;
  for (double threshold : thresholds) {
    options.leg_threshold = threshold;
    const LegDetector detector(classifier, options);
    curve.push_back({threshold, evaluateLegs(detector, labelled, hit_distance),
                     evaluateNegatives(detector, negatives), evaluateNegatives(detector, other)});
  }
  return curve;
}

}  // namespace vision
}  // namespace picker_localisation
