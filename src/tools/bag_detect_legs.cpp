// Offline leg detection on recorded bags.
//   bag_detect_legs --bag FILE --topic TOPIC --out FILE.csv [--model M] [--threshold P]
//                   [--min-cluster-points N] [--jump-distance D] [--max-leg-range R]
// CSV: stamp,x,y,confidence, one row per detected leg (stamp: the scan's header stamp, s; x, y: the scan's
// own frame, m; confidence: the classifier's leg probability).
//   bag_detect_legs --curve --labelled BAG [--labelled BAG ...] [--negatives BAG [--negatives-from F]]
//                   [--other BAG ...] [--model M] [--min-cluster-points N] [--jump-distance D]
//                   [--max-leg-range R] [--decimate K] [--sweep]
// prints the recall vs false-legs-per-scan curve (thresholds 0.2 .. 0.8) of the detector setting:
//   --labelled: leg_tracker "positive_N_extracted" bags (/training_scan + /leg_cluster_positions): recall and
//               precision, a detection within 0.15 m of a label is a hit (one-to-one);
//   --negatives: a recording with no people (every laser topic): every leg is false; --negatives-from F keeps
//               the scans from fraction F of the recording on (0.667: the held-out part of negative_2.bag);
//   --other: unlabelled recordings (e.g. another robot's lasers): legs per scan.
// --decimate K: every K-th beam (the recordings as a K times coarser laser sees them). leg_threshold is the
// threshold at the training lasers' resolution (the detector scales it down for coarser scans, thresholdFor).
// --sweep prints the curve of each minimum cluster size 3, 4, 5 (Algorithm 3's m_c) on all beams, and of the
// default at 1/2 and 1/3 of the beams with and without that threshold scaling.
#include <ros/package.h>

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <string>

#include "picker_localisation/ros/vision_io.h"
#include "picker_localisation/sensors_vision/leg_training.h"

using namespace picker_localisation;

namespace {

constexpr double kHitDistance = 0.15;  // m, as the held-out figures (leg_training.h)

std::vector<core::LaserScan> scansOf(const std::vector<std::string>& bags, double from_fraction) {
  std::vector<core::LaserScan> scans;
  for (const auto& bag : bags) {
    const auto all = ros_adapter::readBagScans(bag);
    if (all.empty()) throw std::runtime_error("no sensor_msgs/LaserScan in " + bag);
    const auto first = static_cast<std::size_t>(from_fraction * static_cast<double>(all.size()));
    for (std::size_t i = first; i < all.size(); ++i) scans.push_back(all[i].scan);
  }
  return scans;
}

struct Setting {
  vision::LegDetectorOptions options;
  std::size_t decimate = 1;  // every k-th beam: the recordings as a k times coarser laser sees them
};

std::string describe(const Setting& s) {
  char text[160];
  std::snprintf(text, sizeof text, "min_cluster_points %zu, %s%s", s.options.segmentation.min_points,
                s.decimate > 1 ? ("1/" + std::to_string(s.decimate) + " of the beams").c_str() : "all beams",
                s.options.threshold_reference_increment > 0.0 ? "" : ", threshold not scaled");
  return text;
}

int printCurves(std::shared_ptr<const vision::LegClassifier> classifier,
                const vision::LegDetectorOptions& options, std::size_t decimate, bool sweep,
                const std::vector<std::string>& labelled_bags, const std::vector<std::string>& negative_bags,
                double negatives_from, const std::vector<std::string>& other_bags) {
  std::vector<vision::LabelledScan> labelled;
  for (const auto& bag : labelled_bags) {
    const auto scans = ros_adapter::readLabelledLegBag(bag);
    if (scans.empty())
      throw std::runtime_error("no labelled scans (/training_scan + /leg_cluster_positions) in " + bag);
    labelled.insert(labelled.end(), scans.begin(), scans.end());
  }
  const auto negatives = scansOf(negative_bags, negatives_from);
  const auto other = scansOf(other_bags, 0.0);
  std::size_t labels = 0;
  for (const auto& s : labelled) labels += s.legs.size();
  std::printf("%zu labelled scans (%zu legs), %zu scans without people, %zu unlabelled scans\n",
              labelled.size(), labels, negatives.size(), other.size());
  std::printf(
      "| setting | leg_threshold | leg recall | precision | false legs / scan (no people) | legs / scan "
      "(unlabelled) |\n"
      "|---|---|---|---|---|---|\n");
  std::vector<Setting> settings{{options, decimate}};
  if (sweep) {
    settings.clear();
    for (std::size_t points : {3, 4, 5}) {
      Setting s{options, 1};
      s.options.segmentation.min_points = points;
      settings.push_back(s);
    }
    for (std::size_t k : {2, 3})
      for (bool scaled : {true, false}) {
        Setting s{options, k};
        if (!scaled) s.options.threshold_reference_increment = 0.0;
        settings.push_back(s);
      }
  }
  for (const auto& setting : settings) {
    auto coarse_labelled = labelled;
    for (auto& s : coarse_labelled) s.scan = vision::decimateScan(s.scan, setting.decimate);
    auto coarse = [&](std::vector<core::LaserScan> scans) {
      for (auto& s : scans) s = vision::decimateScan(s, setting.decimate);
      return scans;
    };
    for (const auto& p : vision::legCurve(classifier, setting.options, coarse_labelled, coarse(negatives),
                                          coarse(other), {0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8}, kHitDistance))
      std::printf("| %s | %.1f | %.3f | %.3f | %.3f | %.3f |\n", describe(setting).c_str(), p.threshold,
                  p.labelled.recall(), p.labelled.precision(), p.negatives.detectionsPerScan(),
                  p.other.detectionsPerScan());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string bag, topic, out, model;
  std::vector<std::string> labelled, negatives, other;
  double negatives_from = 0.0;
  std::size_t decimate = 1;
  bool curve = false, sweep = false;
  vision::LegDetectorOptions options;
  for (int i = 1; i < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--curve" || a == "--sweep") {
      (a == "--curve" ? curve : sweep) = true;
      --i;
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "bag_detect_legs: %s needs a value\n", a.c_str());
      return 2;
    }
    if (a == "--bag")
      bag = argv[i + 1];
    else if (a == "--topic")
      topic = argv[i + 1];
    else if (a == "--out")
      out = argv[i + 1];
    else if (a == "--model")
      model = argv[i + 1];
    else if (a == "--threshold")
      options.leg_threshold = std::stod(argv[i + 1]);
    else if (a == "--min-cluster-points")
      options.segmentation.min_points = std::stoul(argv[i + 1]);
    else if (a == "--jump-distance")
      options.segmentation.jump_distance = std::stod(argv[i + 1]);
    else if (a == "--max-leg-range")
      options.max_leg_range = std::stod(argv[i + 1]);
    else if (a == "--labelled")
      labelled.push_back(argv[i + 1]);
    else if (a == "--negatives")
      negatives.push_back(argv[i + 1]);
    else if (a == "--negatives-from")
      negatives_from = std::stod(argv[i + 1]);
    else if (a == "--other")
      other.push_back(argv[i + 1]);
    else if (a == "--decimate")
      decimate = std::stoul(argv[i + 1]);
    else {
      std::fprintf(stderr, "bag_detect_legs: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  const bool detect_usage = !curve && (bag.empty() || topic.empty() || out.empty());
  const bool curve_usage = curve && (labelled.empty() || !(negatives_from >= 0.0 && negatives_from < 1.0));
  if (detect_usage || curve_usage || (sweep && !curve)) {
    std::fprintf(
        stderr,
        "usage: bag_detect_legs --bag FILE --topic TOPIC --out FILE.csv [--model M] [--threshold P]\n"
        "         [--min-cluster-points N] [--jump-distance D] [--max-leg-range R]\n"
        "       bag_detect_legs --curve --labelled BAG [--labelled BAG ...] [--negatives BAG]\n"
        "         [--negatives-from F in [0, 1)] [--other BAG ...] [--model M] [setting options] "
        "[--sweep]\n");
    return 2;
  }
  try {
    if (model.empty()) {
      const std::string pkg = ros::package::getPath("picker_localisation");
      if (pkg.empty()) throw std::runtime_error("package picker_localisation not found: give --model");
      model = pkg + "/config/leg_classifier.yml";
    }
    auto classifier = std::make_shared<vision::LegClassifier>();
    classifier->load(model);
    if (curve)
      return printCurves(classifier, options, decimate, sweep, labelled, negatives, negatives_from, other);
    vision::LegDetector detector(classifier, options);
    const auto scans = ros_adapter::readBagScans(bag, {topic});
    if (scans.empty()) throw std::runtime_error("no sensor_msgs/LaserScan on " + topic + " in " + bag);
    std::ofstream csv(out);
    if (!csv) throw std::runtime_error("cannot write " + out);
    csv << "stamp,x,y,confidence\n" << std::fixed;
    std::size_t legs = 0;
    for (const auto& s : scans)
      for (const auto& leg : detector.detect(s.scan).legs) {
        csv << std::setprecision(6) << s.scan.stamp << ',' << std::setprecision(4) << leg.position.x() << ','
            << leg.position.y() << ',' << leg.confidence << '\n';
        ++legs;
      }
    std::printf("%zu scans, %zu legs -> %s\n", scans.size(), legs, out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bag_detect_legs: %s\n", e.what());
    return 1;
  }
  return 0;
}
