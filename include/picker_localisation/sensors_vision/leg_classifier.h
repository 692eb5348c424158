// Leg / not-leg classifier on LegFeatures: an OpenCV ml random forest (cv::ml::RTrees). The model file is the
// OpenCV FileStorage YAML written by save() (config/leg_classifier.yml in this package).
#pragma once

#include <opencv2/ml.hpp>

#include <string>
#include <vector>

#include "picker_localisation/sensors_vision/leg_features.h"

namespace picker_localisation {
namespace vision {

struct LegClassifierTrainingOptions {
  int num_trees = 50;          // forest size
  int max_depth = 10;          // per tree
  int min_sample_count = 4;    // a node with fewer samples is not split
  int active_vars = 0;         // features tried per split (0: sqrt(count))
  double positive_prior = 8.0;  // prior weight of the leg class relative to non-legs (<= 0: balance the classes)
  int seed = 1;                // cv::RNG seed used while training (OpenCV's global RNG is re-seeded)
};

class LegClassifier {
 public:
  LegClassifier() = default;

  // Trains from labelled feature vectors (label 1: leg, 0: not a leg). Throws std::invalid_argument when a
  // class is missing.
  void train(const std::vector<LegFeatures>& samples, const std::vector<int>& labels,
             const LegClassifierTrainingOptions& options = {});
  // Loads / saves a model file; load() throws std::runtime_error on a missing or malformed file.
  void load(const std::string& path);
  void save(const std::string& path) const;
  bool trained() const;

  // Fraction of the trees voting "leg", in [0, 1].
  double legProbability(const LegFeatures& features) const;
  std::vector<double> legProbability(const std::vector<LegFeatures>& features) const;

 private:
  cv::Ptr<cv::ml::RTrees> model_;
};

}  // namespace vision
}  // namespace picker_localisation
