#include "picker_localisation/sensors_vision/leg_classifier.h"

#include <fstream>
#include <stdexcept>

namespace picker_localisation {
namespace vision {
namespace {

cv::Mat toMat(const std::vector<LegFeatures>& samples) {
  cv::Mat m(static_cast<int>(samples.size()), LegFeatures::kCount, CV_32F);
  for (std::size_t i = 0; i < samples.size(); ++i)
    for (int k = 0; k < LegFeatures::kCount; ++k) m.at<float>(static_cast<int>(i), k) = samples[i].values[k];
  return m;
}

}  // namespace

void LegClassifier::train(const std::vector<LegFeatures>& samples, const std::vector<int>& labels,
                          const LegClassifierTrainingOptions& options) {
  if (samples.size() != labels.size()) throw std::invalid_argument("LegClassifier::train: size mismatch");
  std::size_t pos = 0;
  for (int l : labels) pos += (l == 1) ? 1 : 0;
  if (pos == 0 || pos == labels.size())
    throw std::invalid_argument("LegClassifier::train: need both leg and non-leg samples");
  cv::Mat x = toMat(samples);
  cv::Mat y(static_cast<int>(labels.size()), 1, CV_32S);
  for (std::size_t i = 0; i < labels.size(); ++i) y.at<int>(static_cast<int>(i)) = labels[i] == 1 ? 1 : 0;

  auto model = cv::ml::RTrees::create();
  model->setMaxDepth(options.max_depth);
  model->setMinSampleCount(options.min_sample_count);
  model->setActiveVarCount(options.active_vars);
  model->setCalculateVarImportance(false);
  model->setTermCriteria(cv::TermCriteria(cv::TermCriteria::MAX_ITER, options.num_trees, 0.0));
  {
    // Legs are rare among clusters; the prior on the leg class offsets part of the imbalance (fully balanced
    // priors, positive_prior <= 0, gave too many false legs on the negative recording).
    const double neg = static_cast<double>(labels.size() - pos);
    const double w = options.positive_prior > 0.0 ? options.positive_prior : neg / static_cast<double>(pos);
    cv::Mat priors = (cv::Mat_<float>(1, 2) << 1.0f, static_cast<float>(w));
    model->setPriors(priors);
  }
  cv::theRNG().state = static_cast<uint64>(options.seed);  // RTrees samples through OpenCV's RNG
  // Categorical response (classification), ordered features.
  cv::Mat var_type(1, LegFeatures::kCount + 1, CV_8U, cv::Scalar(cv::ml::VAR_ORDERED));
  var_type.at<uchar>(LegFeatures::kCount) = cv::ml::VAR_CATEGORICAL;
  auto data =
      cv::ml::TrainData::create(x, cv::ml::ROW_SAMPLE, y, cv::noArray(), cv::noArray(), cv::noArray(), var_type);
  if (!model->train(data)) throw std::runtime_error("LegClassifier::train: OpenCV training failed");
  model_ = model;
}

void LegClassifier::load(const std::string& path) {
  std::ifstream probe(path);
  if (!probe) throw std::runtime_error("LegClassifier: cannot read model file " + path);
  cv::Ptr<cv::ml::RTrees> model;
  try {
    model = cv::ml::RTrees::load(path);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("LegClassifier: malformed model file " + path + ": " + e.what());
  }
  if (model.empty() || !model->isTrained() || model->getVarCount() != LegFeatures::kCount)
    throw std::runtime_error("LegClassifier: " + path + " is not a trained " +
                             std::to_string(LegFeatures::kCount) + "-feature random forest");
  model_ = model;
}

void LegClassifier::save(const std::string& path) const {
  if (!trained()) throw std::runtime_error("LegClassifier::save: not trained");
  model_->save(path);
}

bool LegClassifier::trained() const { return !model_.empty() && model_->isTrained(); }

std::vector<double> LegClassifier::legProbability(const std::vector<LegFeatures>& features) const {
  std::vector<double> out(features.size(), 0.0);
  if (!trained()) throw std::runtime_error("LegClassifier: no model loaded");
  if (features.empty()) return out;
  cv::Mat votes;
  model_->getVotes(toMat(features), votes, 0);
  // First row: class labels; then one row of vote counts per sample.
  int leg_col = -1;
  for (int c = 0; c < votes.cols; ++c)
    if (votes.at<int>(0, c) == 1) leg_col = c;
  if (leg_col < 0) return out;
  for (std::size_t i = 0; i < features.size(); ++i) {
    double total = 0.0;
    for (int c = 0; c < votes.cols; ++c) total += votes.at<int>(static_cast<int>(i) + 1, c);
    out[i] = total > 0.0 ? votes.at<int>(static_cast<int>(i) + 1, leg_col) / total : 0.0;
  }
  return out;
}

double LegClassifier::legProbability(const LegFeatures& features) const {
  return legProbability(std::vector<LegFeatures>{features}).front();
}

}  // namespace vision
}  // namespace picker_localisation
