// Trains the leg classifier from the labelled leg_tracker bags and writes the OpenCV model file.
//   train_leg_classifier --data DIR --out config/leg_classifier.yml [--sweep] [--features F.csv]
//                        [--augment-decimate K]
// (--features writes every training / held-out feature vector; --sweep prints held-out recall / precision / false legs per scan for thresholds 0.1..0.9)
// (--augment-decimate K also trains on the scans at 1/2 .. 1/K of their beams: measured worse, not used for
// the committed model; docs/readme/sensors_vision.md "Leg curves")
// DIR holds positive_{1..4}_extracted.bag and negative_2.bag. Split (fixed, see leg_training.h): positives 1-3
// and the first two thirds of negative_2 train; positive_4 and the last third of negative_2 are held out and
// evaluated here (and in test_leg_detector_data).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "picker_localisation/ros/vision_io.h"

using namespace picker_localisation;

// Background clusters of the positive recordings farther than this from every labelled leg are negatives, m.
constexpr double kUnlabelledNegativeDistance = 0.5;

int main(int argc, char** argv) {
  std::string data, out, dump;
  double hit = 0.15;
  bool sweep = false;
  std::size_t augment_decimate = 1;
  for (int i = 1; i < argc; i += 2) {
    if (!std::strcmp(argv[i], "--sweep")) {
      sweep = true;
      --i;
    } else if (i + 1 < argc && !std::strcmp(argv[i], "--data")) data = argv[i + 1];
    else if (i + 1 < argc && !std::strcmp(argv[i], "--out")) out = argv[i + 1];
    else if (i + 1 < argc && !std::strcmp(argv[i], "--features")) dump = argv[i + 1];
    else if (i + 1 < argc && !std::strcmp(argv[i], "--augment-decimate")) augment_decimate = std::stoul(argv[i + 1]);
    else {
      std::fprintf(stderr, "unknown option %s\n", argv[i]);
      return 2;
    }
  }
  if (data.empty() || out.empty()) {
    std::fprintf(stderr, "usage: train_leg_classifier --data DIR --out FILE.yml [--sweep]\n");
    return 2;
  }
  try {
    std::vector<vision::LabelledScan> train_pos, test_pos;
    for (int n = 1; n <= 4; ++n) {
      auto scans = ros_adapter::readLabelledLegBag(data + "/positive_" + std::to_string(n) + "_extracted.bag");
      auto& dst = n <= 3 ? train_pos : test_pos;
      dst.insert(dst.end(), scans.begin(), scans.end());
    }
    const auto neg = ros_adapter::readBagScans(data + "/negative_2.bag");
    const std::size_t split = vision::negativeTrainCount(neg.size());
    std::vector<core::LaserScan> train_neg, test_neg;
    for (std::size_t i = 0; i < neg.size(); ++i) (i < split ? train_neg : test_neg).push_back(neg[i].scan);

    vision::LegDetectorOptions options;
    std::vector<vision::LegFeatures> samples;
    std::vector<int> labels;
    vision::collectTrainingSamples(train_pos, train_neg, options, hit, kUnlabelledNegativeDistance, samples, labels);
    // The same training scans as lasers 2..K times coarser see them (every k-th beam): the forest learns legs
    // at several point densities.
    for (std::size_t k = 2; k <= augment_decimate; ++k) {
      std::vector<vision::LabelledScan> pos;
      std::vector<core::LaserScan> negs;
      for (const auto& ls : train_pos) pos.push_back({vision::decimateScan(ls.scan, k), ls.legs});
      for (const auto& sc : train_neg) negs.push_back(vision::decimateScan(sc, k));
      vision::collectTrainingSamples(pos, negs, options, hit, kUnlabelledNegativeDistance, samples, labels);
    }
    std::size_t npos = 0;
    for (int l : labels) npos += l;
    std::printf("training: %zu positive and %zu negative clusters (%zu + %zu scans)\n", npos, labels.size() - npos,
                train_pos.size(), train_neg.size());
    auto classifier = std::make_shared<vision::LegClassifier>();
    if (!dump.empty()) {
      std::ofstream csv(dump);
      csv << "set,label";
      for (int k = 0; k < vision::LegFeatures::kCount; ++k) csv << ',' << vision::LegFeatures::name(k);
      csv << '\n';
      auto write = [&](const char* set, const std::vector<vision::LegFeatures>& f, const std::vector<int>& l) {
        for (std::size_t i = 0; i < f.size(); ++i) {
          csv << set << ',' << l[i];
          for (float v : f[i].values) csv << ',' << v;
          csv << '\n';
        }
      };
      write("train", samples, labels);
      std::vector<vision::LegFeatures> ts;
      std::vector<int> tl;
      vision::collectTrainingSamples(test_pos, test_neg, options, hit, kUnlabelledNegativeDistance, ts, tl);
      write("test", ts, tl);
    }
    vision::LegClassifierTrainingOptions topt;
    classifier->train(samples, labels, topt);
    classifier->save(out);
    std::printf("wrote %s\n", out.c_str());

    vision::LegDetector detector(classifier, options);
    const auto e = vision::evaluateLegs(detector, test_pos, hit);
    const auto n = vision::evaluateNegatives(detector, test_neg);
    std::printf("held out positive_4: %zu scans, %zu labels, %zu detections, recall %.3f, precision %.3f\n", e.scans,
                e.labels, e.detections, e.recall(), e.precision());
    std::printf("held out negative_2 (last third): %zu scans, %.3f false legs per scan\n", n.scans,
                n.detectionsPerScan());
    if (sweep)
      for (const auto& p : vision::legCurve(classifier, options, test_pos, test_neg, {},
                                            {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9}, hit))
        std::printf("  threshold %.1f: recall %.3f precision %.3f false/scan %.3f\n", p.threshold,
                    p.labelled.recall(), p.labelled.precision(), p.negatives.detectionsPerScan());
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "train_leg_classifier: %s\n", ex.what());
    return 1;
  }
  return 0;
}
