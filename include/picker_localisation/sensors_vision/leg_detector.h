// Scan -> clusters (Algorithm 3) -> features -> leg classifier -> legs paired into people. ROS-free; the
// offline experiment runner calls it in-process on simulated scans.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <vector>

#include "picker_localisation/sensors_vision/laser_scan.h"
#include "picker_localisation/sensors_vision/leg_classifier.h"

namespace picker_localisation {
namespace vision {

struct Leg {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // cluster centroid, m, scan frame
  double confidence = 0.0;                              // classifier leg probability
  std::size_t cluster_index = 0;                        // index into LegDetection::clusters
};

struct Person {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // m, frame of the legs
  double confidence = 0.0;                              // [0, 1]
  int leg_a = -1, leg_b = -1;                           // indices into the legs; leg_b == -1 for a single leg
};

struct LegDetection {
  double stamp = 0.0;
  std::vector<ScanCluster> clusters;  // every segmented cluster
  std::vector<Leg> legs;              // clusters classified as legs
  std::vector<Person> people;         // legs paired into people
};

struct LegDetectorOptions {
  SegmentationOptions segmentation;
  double leg_threshold = 0.6;          // minimum leg probability for a cluster to be a leg, at the angular
                                       // resolution of the training lasers (see thresholdFor)
  double threshold_reference_increment = 0.006136;  // rad (0.3516 deg), the training lasers' beam spacing; a
                                                    // coarser laser's threshold is scaled down by the ratio
                                                    // (0: no scaling)
  double max_leg_range = 8.0;          // clusters farther from the sensor are ignored, m
  double max_leg_width = 0.5;          // clusters wider than this are never legs, m
  double max_pair_distance = 0.7;      // two legs closer than this may be one person, m
  bool single_leg_people = true;       // an unpaired leg is a person (other leg occluded) ...
  double single_leg_factor = 0.5;      // ... with its confidence scaled by this factor
};

// Range and width gates applied before classification: clusters outside them are never legs.
bool isLegCandidate(const ScanCluster& cluster, const LegDetectorOptions& options);

// Pairs legs into people: greedy by increasing distance, each leg used once, pairs closer than
// max_pair_distance; a pair's position is the midpoint and its confidence the mean leg probability.
std::vector<Person> pairLegs(const std::vector<Leg>& legs, const LegDetectorOptions& options);

// The leg probability threshold for a scan of this angular increment: leg_threshold x min(1, reference /
// increment). The forest sees fewer points per leg on a coarser laser and its probabilities drop roughly in
// proportion (measured on the held-out real scans at 1/2 and 1/3 of their beams,
// docs/readme/sensors_vision.md "Leg curves": the same recall / false-leg trade-off appears at 0.6, 0.3 and
// 0.2), so a fixed threshold silently trades most of a coarse laser's legs away. Finer lasers keep
// leg_threshold.
double thresholdFor(const LegDetectorOptions& options, double angle_increment);

class LegDetector {
 public:
  LegDetector(std::shared_ptr<const LegClassifier> classifier, LegDetectorOptions options = {});
  LegDetection detect(const core::LaserScan& scan) const;
  const LegDetectorOptions& options() const { return options_; }

 private:
  std::shared_ptr<const LegClassifier> classifier_;
  LegDetectorOptions options_;
};

}  // namespace vision
}  // namespace picker_localisation
