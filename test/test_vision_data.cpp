// sensors_vision on real data (no roscore):
// - the committed leg classifier (config/leg_classifier.yml) on the HELD-OUT labelled scans of
//   ../shared/data/leg_tracker (positive_4_extracted.bag; a detection within 0.15 m of a labelled leg is a
//   hit, one-to-one) and on the held-out last third of negative_2.bag (no people: every leg is false);
// - the HOG people detector on four frames of Debian opencv-doc's vtest.avi with boxes labelled by hand.
// Bounds are set with a margin below/above the figures measured at commit time (docs/readme/sensors_vision.md).
#include <gtest/gtest.h>

#include <opencv2/videoio.hpp>

#include <filesystem>
#include <fstream>

#include "picker_localisation/ros/vision_io.h"
#include "picker_localisation/sensors_vision/person_box_detector.h"

using namespace picker_localisation;
using namespace picker_localisation::vision;

namespace {

const std::string kLegData = std::string(PL_SHARED_DATA) + "/leg_tracker/rosbags/training_scans_res=0.33";
const std::string kModel = std::string(PL_PACKAGE_DIR) + "/config/leg_classifier.yml";
const std::string kVideo = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";

std::shared_ptr<LegClassifier> loadModel() {
  auto c = std::make_shared<LegClassifier>();
  c->load(kModel);
  return c;
}

}  // namespace

TEST(LegDetectorRealData, HeldOutPositivesRecallAndPrecision) {
  const auto scans = ros_adapter::readLabelledLegBag(kLegData + "/positive_4_extracted.bag");
  ASSERT_EQ(scans.size(), 295u);
  LegDetector detector(loadModel());
  const auto e = evaluateLegs(detector, scans, 0.15);
  EXPECT_EQ(e.labels, 415u);
  RecordProperty("recall", std::to_string(e.recall()));
  RecordProperty("precision", std::to_string(e.precision()));
  std::printf("held-out positive_4: recall %.3f precision %.3f (%zu labels, %zu detections)\n", e.recall(),
              e.precision(), e.labels, e.detections);
  EXPECT_GE(e.recall(), PL_MIN_LEG_RECALL);
  EXPECT_GE(e.precision(), PL_MIN_LEG_PRECISION);
}

TEST(LegDetectorRealData, HeldOutNegativesFalseLegsPerScan) {
  const auto all = ros_adapter::readBagScans(kLegData + "/negative_2.bag");
  ASSERT_GT(all.size(), 1000u);
  std::vector<core::LaserScan> held;
  for (std::size_t i = negativeTrainCount(all.size()); i < all.size(); ++i) held.push_back(all[i].scan);
  LegDetector detector(loadModel());
  const auto e = evaluateNegatives(detector, held);
  std::printf("held-out negative_2: %zu scans, %.3f false legs per scan\n", e.scans, e.detectionsPerScan());
  EXPECT_LE(e.detectionsPerScan(), PL_MAX_FALSE_LEGS_PER_SCAN);
}

TEST(LegClassifierFile, MissingAndMalformedModelsThrow) {
  LegClassifier c;
  EXPECT_THROW(c.load("/nonexistent/leg_classifier.yml"), std::runtime_error);
  const std::string bad = (std::filesystem::temp_directory_path() / "pl_vision_bad_model.yml").string();
  { std::ofstream(bad) << "%YAML:1.0\nnot_a_model: 3\n"; }
  EXPECT_THROW(c.load(bad), std::runtime_error);
  EXPECT_FALSE(c.trained());
}

namespace {

struct LabelledBox {
  int frame;
  cv::Rect box;
};

// Hand-labelled people (x1, y1, x2, y2 in the 768 x 576 frames), every person at least half visible.
const std::vector<LabelledBox> kPeople = {
    {0, cv::Rect(cv::Point(253, 220), cv::Point(283, 308))},   {0, cv::Rect(cv::Point(500, 157), cv::Point(530, 233))},
    {0, cv::Rect(cv::Point(640, 240), cv::Point(685, 322))},   {200, cv::Rect(cv::Point(83, 153), cv::Point(110, 215))},
    {200, cv::Rect(cv::Point(220, 191), cv::Point(250, 267))}, {200, cv::Rect(cv::Point(487, 145), cv::Point(518, 222))},
    {200, cv::Rect(cv::Point(615, 265), cv::Point(652, 368))}, {200, cv::Rect(cv::Point(705, 253), cv::Point(745, 354))},
    {200, cv::Rect(cv::Point(678, 98), cv::Point(698, 154))},  {200, cv::Rect(cv::Point(702, 101), cv::Point(722, 155))},
    {400, cv::Rect(cv::Point(273, 200), cv::Point(302, 286))}, {400, cv::Rect(cv::Point(589, 140), cv::Point(617, 204))},
    {400, cv::Rect(cv::Point(687, 300), cv::Point(745, 412))}, {600, cv::Rect(cv::Point(188, 145), cv::Point(214, 214))},
    {600, cv::Rect(cv::Point(568, 200), cv::Point(597, 288))}, {600, cv::Rect(cv::Point(670, 208), cv::Point(705, 296))},
    {600, cv::Rect(cv::Point(455, 302), cv::Point(505, 418))}, {600, cv::Rect(cv::Point(640, 305), cv::Point(670, 412))},
    {600, cv::Rect(cv::Point(284, 432), cv::Point(332, 576))}};

// A detection matches a person when it contains the person's centre and its height is 0.6-2.2 times theirs
// (HOG boxes include a margin around the body); one detection per person.
bool matches(const cv::Rect& det, const cv::Rect& person) {
  const cv::Point c(person.x + person.width / 2, person.y + person.height / 2);
  const double ratio = static_cast<double>(det.height) / person.height;
  return det.contains(c) && ratio >= 0.6 && ratio <= 2.2;
}

}  // namespace

TEST(HogPersonDetectorRealData, VtestHandLabelledFrames) {
  ASSERT_TRUE(std::filesystem::exists(kVideo)) << "install Debian's opencv-doc (scripts/apt-packages.txt)";
  cv::VideoCapture cap(kVideo);
  ASSERT_TRUE(cap.isOpened());
  HogOptions options;
  options.resize = 1.5;  // people are 60-110 px tall here, smaller than the 64 x 128 HOG window
  HogPersonDetector hog(options);
  std::size_t found = 0, detections = 0, frames = 0;
  cv::Mat img;
  for (int index = 0; cap.read(img) && index <= 600; ++index) {
    if (index % 200 != 0) continue;
    ++frames;
    auto boxes = hog.detect(img);
    detections += boxes.size();
    std::vector<char> used(boxes.size(), 0);
    for (const auto& p : kPeople) {
      if (p.frame != index) continue;
      for (std::size_t b = 0; b < boxes.size(); ++b)
        if (!used[b] && matches(boxes[b].box, p.box)) {
          used[b] = 1;
          ++found;
          break;
        }
    }
    for (const auto& b : boxes) {
      EXPECT_GE(b.box.x, 0);
      EXPECT_LE(b.box.x + b.box.width, img.cols);
      EXPECT_GT(b.confidence, 0.0);
      EXPECT_LE(b.confidence, 1.0);
    }
  }
  ASSERT_EQ(frames, 4u);
  const double recall = static_cast<double>(found) / kPeople.size();
  const double false_per_frame = static_cast<double>(detections - found) / frames;
  std::printf("vtest.avi: %zu of %zu people found (recall %.3f), %.2f false boxes per frame\n", found,
              kPeople.size(), recall, false_per_frame);
  EXPECT_GE(recall, 0.75);          // measured 17 / 19 = 0.895
  EXPECT_LE(false_per_frame, 2.5);  // measured 1.5
  // A uniform image holds no people.
  EXPECT_TRUE(hog.detect(cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 120, 90))).empty());
  EXPECT_TRUE(hog.detect(cv::Mat()).empty());
}
