// Offline leg detection on a recorded bag:
//   bag_detect_legs --bag FILE --topic TOPIC --out FILE.csv [--model config/leg_classifier.yml] [--threshold P]
// CSV: stamp,x,y,confidence, one row per detected leg (stamp: the scan's header stamp, s; x, y: the scan's own
// frame, m; confidence: the classifier's leg probability).
#include <ros/package.h>

#include <cstdio>
#include <fstream>
#include <iomanip>
#include <string>

#include "picker_localisation/ros/vision_io.h"

using namespace picker_localisation;

int main(int argc, char** argv) {
  std::string bag, topic, out, model;
  vision::LegDetectorOptions options;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--bag") bag = argv[i + 1];
    else if (a == "--topic") topic = argv[i + 1];
    else if (a == "--out") out = argv[i + 1];
    else if (a == "--model") model = argv[i + 1];
    else if (a == "--threshold") options.leg_threshold = std::stod(argv[i + 1]);
    else {
      std::fprintf(stderr, "bag_detect_legs: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  if (bag.empty() || topic.empty() || out.empty()) {
    std::fprintf(stderr, "usage: bag_detect_legs --bag FILE --topic TOPIC --out FILE.csv [--model M] [--threshold P]\n");
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
