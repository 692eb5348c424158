// bench_legs: leg detector time per scan (segmentation + features + forest + pairing) for 512 and 1024 beams
// over 270 deg, and the camera detector's time per 640 x 480 frame (HOG; frame 0 of vtest.avi resized when
// opencv-doc is installed, else a synthetic image). Run: rosrun picker_localisation bench_legs [--model M]
#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <cmath>
#include <random>

#include "picker_localisation/sensors_vision/leg_detector.h"
#include "picker_localisation/sensors_vision/person_box_detector.h"

using namespace picker_localisation;
using namespace picker_localisation::vision;

namespace {

std::string g_model = PL_LEG_MODEL;

// A 10 m x 8 m room seen from its centre with two people (four legs, radius 6 cm) and six table legs; beams
// over 270 deg with 1 cm range noise (seeded).
core::LaserScan syntheticScan(int beams) {
  core::LaserScan s;
  s.angle_min = -0.75 * M_PI;
  s.angle_increment = 1.5 * M_PI / beams;
  s.range_min = 0.05;
  s.range_max = 20.0;
  const std::vector<Eigen::Vector3d> circles = {{1.5, 0.3, 0.06},  {1.5, 0.55, 0.06}, {3.0, -1.0, 0.06},
                                                {3.1, -1.3, 0.06}, {-2.0, 2.0, 0.03}, {-2.0, 2.8, 0.03},
                                                {-2.8, 2.0, 0.03}, {-2.8, 2.8, 0.03}, {2.0, 3.0, 0.02},
                                                {2.4, 3.0, 0.02}};
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int i = 0; i < beams; ++i) {
    const double a = s.angle(static_cast<std::size_t>(i));
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    double r = std::min(std::abs(d.x()) > 1e-9 ? 5.0 / std::abs(d.x()) : 1e9,
                        std::abs(d.y()) > 1e-9 ? 4.0 / std::abs(d.y()) : 1e9);
    for (const auto& c : circles) {
      const Eigen::Vector2d o = c.head<2>();
      const double b = d.dot(o), disc = b * b - o.squaredNorm() + c.z() * c.z();
      if (disc >= 0.0 && b - std::sqrt(disc) > 0.0) r = std::min(r, b - std::sqrt(disc));
    }
    s.ranges.push_back(static_cast<float>(r + noise(rng)));
  }
  return s;
}

void BM_LegDetectorPerScan(benchmark::State& state) {
  auto classifier = std::make_shared<LegClassifier>();
  classifier->load(g_model);
  LegDetector detector(classifier);
  const auto scan = syntheticScan(static_cast<int>(state.range(0)));
  std::size_t legs = 0;
  for (auto _ : state) {
    auto d = detector.detect(scan);
    legs = d.legs.size();
    benchmark::DoNotOptimize(d);
  }
  state.counters["legs"] = static_cast<double>(legs);
}
BENCHMARK(BM_LegDetectorPerScan)->Arg(512)->Arg(1024)->Unit(benchmark::kMicrosecond);

void BM_HogPerFrame640x480(benchmark::State& state) {
  cv::Mat frame;
  cv::VideoCapture cap("/usr/share/doc/opencv-doc/examples/data/vtest.avi");
  if (cap.isOpened() && cap.read(frame)) {
    cv::resize(frame, frame, cv::Size(640, 480));
  } else {
    frame = cv::Mat(480, 640, CV_8UC3);
    cv::randu(frame, 0, 255);
  }
  HogPersonDetector hog;
  std::size_t boxes = 0;
  for (auto _ : state) {
    auto b = hog.detect(frame);
    boxes = b.size();
    benchmark::DoNotOptimize(b);
  }
  state.counters["boxes"] = static_cast<double>(boxes);
}
BENCHMARK(BM_HogPerFrame640x480)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--model") g_model = argv[i + 1];
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
