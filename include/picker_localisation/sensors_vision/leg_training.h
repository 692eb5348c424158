// Training-set extraction and held-out evaluation of the leg detector on labelled scans (ROS-free; the bag
// reading lives in the ROS library, see ros/leg_bag_reader.h).
#pragma once

#include <Eigen/Core>

#include <memory>
#include <vector>

#include "picker_localisation/sensors_vision/leg_detector.h"

namespace picker_localisation {
namespace vision {

struct LabelledScan {
  core::LaserScan scan;
  std::vector<Eigen::Vector2d> legs;  // labelled leg positions, scan frame, m
};

// Clusters of labelled scans whose centroid lies within `match_distance` of a label are positives; clusters of
// those scans farther than `unlabelled_negative_distance` (> 0) from every label are negatives (the background of
// the positive recordings; the labelling tool marked the legs of the person in view), the rest are skipped.
// Every cluster of the negative scans is a negative. Clusters failing the detector's range/width gates are skipped, as the detector never classifies
// them.
void collectTrainingSamples(const std::vector<LabelledScan>& positives, const std::vector<core::LaserScan>& negatives,
                            const LegDetectorOptions& options, double match_distance,
                            double unlabelled_negative_distance,
                            std::vector<LegFeatures>& samples, std::vector<int>& labels);

struct LegEvaluation {
  std::size_t scans = 0, labels = 0, detections = 0;
  std::size_t true_positives = 0;  // detections matched one-to-one to a label within the hit distance
  double recall() const { return labels ? static_cast<double>(true_positives) / labels : 0.0; }
  double precision() const { return detections ? static_cast<double>(true_positives) / detections : 1.0; }
  double detectionsPerScan() const { return scans ? static_cast<double>(detections) / scans : 0.0; }
};

// Leg detections vs labels, matched one-to-one (Munkres on distance, pairs beyond hit_distance rejected).
LegEvaluation evaluateLegs(const LegDetector& detector, const std::vector<LabelledScan>& scans, double hit_distance);
// Scans with no people: every leg detected is false.
LegEvaluation evaluateNegatives(const LegDetector& detector, const std::vector<core::LaserScan>& scans);

// One point of a recall vs false-legs-per-scan curve: the detector at `threshold` on labelled scans (recall,
// precision) and on scans without people (false legs per scan); `other` counts legs per scan on unlabelled
// scans (e.g. another robot's lasers: an upper bound on its false legs when nobody walks there).
struct LegCurvePoint {
  double threshold = 0.0;
  LegEvaluation labelled;
  LegEvaluation negatives;
  LegEvaluation other;
};

// The curve of one detector setting over `thresholds` (`options.leg_threshold` is replaced at each point).
std::vector<LegCurvePoint> legCurve(std::shared_ptr<const LegClassifier> classifier,
                                    LegDetectorOptions options, const std::vector<LabelledScan>& labelled,
                                    const std::vector<core::LaserScan>& negatives,
                                    const std::vector<core::LaserScan>& other,
                                    const std::vector<double>& thresholds, double hit_distance);

}  // namespace vision
}  // namespace picker_localisation

namespace picker_localisation {
namespace vision {

// The fixed held-out split used by train_leg_classifier and the real-data tests: labelled positives
// positive_1..3 train, positive_4 is held out; of the negative bag (all laser topics in recording order) the
// first two thirds of the scans train and the last third is held out.
constexpr double kNegativeTrainFraction = 2.0 / 3.0;
inline std::size_t negativeTrainCount(std::size_t total) {
  return static_cast<std::size_t>(static_cast<double>(total) * kNegativeTrainFraction);
}

}  // namespace vision
}  // namespace picker_localisation
