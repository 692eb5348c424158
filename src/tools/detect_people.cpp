// Offline person boxes on a video or a folder of images:
//   detect_people --video FILE | --images DIR --out FILE.csv [--model default|daimler] [--resize F]
//                 [--scale S] [--hit-threshold T] [--min-confidence C] [--onnx MODEL.onnx] [--max-frames N]
// CSV: frame,x,y,width,height,confidence (frame: the image's file name, or the video frame index; x, y:
// top-left corner in pixels of the original image). HOG people detector (config/vision.yaml's camera_detector
// defaults) unless --onnx is given.
// Scored against hand labels (frame,x1,y1,x2,y2,person|ignore; e.g. test/data/vtest_people.csv), only the
// labelled frames are run:
//   detect_people --video FILE --labels LABELS.csv [options]  -> recall, precision, false boxes, ms per frame
//   detect_people --video FILE --labels LABELS.csv --sweep    -> that table for every HOG option set below,
//                 each at several confidence cuts, the cost relative to one native default-HOG pass (same run)
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "picker_localisation/sensors_vision/box_evaluation.h"
#include "picker_localisation/sensors_vision/person_box_detector.h"

using namespace picker_localisation::vision;

namespace {

struct Frame {
  std::string name;
  cv::Mat image;
};

// Calls fn(name, image) for every frame of a video or image folder (only the frames in `wanted` when it is
// not empty), up to max_frames (0: all).
template <typename Fn>
void forEachFrame(const std::string& video, const std::string& images,
                  const std::map<std::string, std::vector<LabelledPerson>>& wanted, std::size_t max_frames,
                  Fn fn) {
  std::size_t count = 0;
  auto keep = [&](const std::string& name) { return wanted.empty() || wanted.count(name) > 0; };
  auto full = [&] { return max_frames > 0 && count >= max_frames; };
  if (!video.empty()) {
    cv::VideoCapture cap(video);
    if (!cap.isOpened()) throw std::runtime_error("cannot open video " + video);
    cv::Mat frame;
    for (int index = 0; !full() && cap.read(frame); ++index)
      if (keep(std::to_string(index))) {
        fn(std::to_string(index), frame);
        ++count;
      }
    return;
  }
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(images))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    if (full()) break;
    if (!keep(f.filename().string())) continue;
    const cv::Mat img = cv::imread(f.string(), cv::IMREAD_COLOR);
    if (img.empty()) continue;  // not an image
    fn(f.filename().string(), img);
    ++count;
  }
}

// Runs the detector on every frame (timed: the tool's own wall clock, never inside the detector) and scores
// the boxes of confidence >= each cut.
std::vector<BoxScore> score(const PersonBoxDetector& detector, const std::vector<Frame>& frames,
                            const std::map<std::string, std::vector<LabelledPerson>>& labels,
                            const std::vector<double>& cuts) {
  std::vector<BoxScore> scores(cuts.size());
  for (const auto& f : frames) {
    const auto start = std::chrono::steady_clock::now();
    const auto boxes = detector.detect(f.image);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const auto it = labels.find(f.name);
    const std::vector<LabelledPerson> none;
    for (std::size_t c = 0; c < cuts.size(); ++c) {
      std::vector<PersonBox> kept;
      for (const auto& b : boxes)
        if (b.confidence >= cuts[c]) kept.push_back(b);
      auto s = scoreFrame(kept, it == labels.end() ? none : it->second);
      s.seconds = seconds;
      scores[c].add(s);
    }
  }
  return scores;
}

std::string describe(const HogOptions& o) {
  char name[96];
  std::snprintf(name, sizeof name, "%s, resize %.2f, scale %.2f, hit_threshold %.1f", o.model.c_str(),
                o.resize, o.scale, o.hit_threshold);
  return name;
}

void printRow(const std::string& option, double cut, const BoxScore& s, double baseline_ms) {
  char cost[32] = "-";
  if (baseline_ms > 0) std::snprintf(cost, sizeof cost, "%.2fx", s.msPerFrame() / baseline_ms);
  std::printf("| %s | %.2f | %.3f (%zu / %zu) | %.3f | %.2f | %.0f | %s |\n", option.c_str(), cut, s.recall(),
              s.found, s.people, s.precision(), s.falsePerFrame(), s.msPerFrame(), cost);
}

const char* kTableHeader =
    "| option | min_confidence | recall | precision | false boxes / frame | ms / frame | cost vs native "
    "default |\n"
    "|---|---|---|---|---|---|---|\n";

int sweep(const std::vector<Frame>& frames,
          const std::map<std::string, std::vector<LabelledPerson>>& labels) {
  auto make = [](const std::string& model, double resize, double scale, double hit) {
    HogOptions o;
    o.model = model;
    o.resize = resize;
    o.scale = scale;
    o.hit_threshold = hit;
    o.min_confidence = 0.0;  // cut afterwards
    return o;
  };
  // The first row is the cost baseline (one native pass of OpenCV's default people detector).
  const std::vector<HogOptions> settings{
      make("default", 1.0, 1.05, 0.0),  make("daimler", 1.0, 1.05, 0.0),  make("default", 1.5, 1.05, 0.0),
      make("default", 2.0, 1.05, 0.0),  make("daimler", 1.25, 1.08, 0.0), make("daimler", 1.5, 1.10, 0.0),
      make("default", 1.5, 1.10, 0.0),  make("default", 1.5, 1.10, -0.1), make("default", 1.5, 1.10, -0.2),
      make("default", 1.5, 1.09, -0.2), make("default", 1.6, 1.10, -0.3), make("default", 1.4, 1.10, -0.2)};
  const std::vector<double> cuts{0.0, 0.3, 0.5, 0.7};
  std::printf("%zu frames\n%s", frames.size(), kTableHeader);
  double baseline_ms = 0.0;
  for (const auto& setting : settings) {
    const HogPersonDetector detector(setting);
    const auto scores = score(detector, frames, labels, cuts);
    if (baseline_ms == 0.0) baseline_ms = scores.front().msPerFrame();
    for (std::size_t c = 0; c < cuts.size(); ++c) printRow(describe(setting), cuts[c], scores[c], baseline_ms);
  }
  return 0;
}

// The detector the node would build from these options (camera_detector's schema decides HOG or ONNX).
CameraDetectorOptions cameraOptions(const HogOptions& hog, const std::string& onnx) {
  CameraDetectorOptions camera;
  camera.hog = hog;
  camera.onnx_model = camera.onnx.model_path = onnx;
  return camera;
}

}  // namespace

int main(int argc, char** argv) {
  std::string video, images, out, onnx, labels_file;
  std::size_t max_frames = 0;  // 0: all
  bool do_sweep = false;
  HogOptions hog;
  for (int i = 1; i < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--sweep") {
      do_sweep = true;
      --i;
      continue;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "detect_people: %s needs a value\n", a.c_str());
      return 2;
    }
    if (a == "--video")
      video = argv[i + 1];
    else if (a == "--images")
      images = argv[i + 1];
    else if (a == "--out")
      out = argv[i + 1];
    else if (a == "--resize")
      hog.resize = std::stod(argv[i + 1]);
    else if (a == "--model")
      hog.model = argv[i + 1];
    else if (a == "--scale")
      hog.scale = std::stod(argv[i + 1]);
    else if (a == "--hit-threshold")
      hog.hit_threshold = std::stod(argv[i + 1]);
    else if (a == "--min-confidence")
      hog.min_confidence = std::stod(argv[i + 1]);
    else if (a == "--labels")
      labels_file = argv[i + 1];
    else if (a == "--onnx")
      onnx = argv[i + 1];
    else if (a == "--max-frames")
      max_frames = std::stoul(argv[i + 1]);
    else {
      std::fprintf(stderr, "detect_people: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  if ((out.empty() && labels_file.empty()) || video.empty() == images.empty() ||
      (do_sweep && labels_file.empty())) {
    std::fprintf(
        stderr,
        "usage: detect_people --video FILE|--images DIR (--out FILE.csv | --labels LABELS.csv [--sweep])\n"
        "       [--model default|daimler] [--resize F] [--scale S] [--hit-threshold T] [--min-confidence C]\n"
        "       [--onnx M] [--max-frames N]\n");
    return 2;
  }
  try {
    if (!labels_file.empty()) {
      const auto labels = labelsByFrame(readPeopleLabels(labels_file));
      std::vector<Frame> frames;
      forEachFrame(video, images, labels, max_frames, [&](const std::string& name, const cv::Mat& img) {
        frames.push_back({name, img.clone()});
      });
      if (frames.empty()) throw std::runtime_error("no labelled frame found in the input");
      if (do_sweep) return sweep(frames, labels);
      const CameraDetectorOptions camera = cameraOptions(hog, onnx);
      const double cut = 0.0;  // the detector applies its own min_confidence
      const auto s = score(*camera.makeDetector(), frames, labels, {cut}).front();
      std::printf("%zu frames\n%s", frames.size(), kTableHeader);
      printRow(onnx.empty() ? describe(hog) : onnx, onnx.empty() ? hog.min_confidence : camera.onnx.min_confidence,
               s, 0.0);
      return 0;
    }
    const auto detector = cameraOptions(hog, onnx).makeDetector();
    std::ofstream csv(out);
    if (!csv) throw std::runtime_error("cannot write " + out);
    csv << "frame,x,y,width,height,confidence\n";
    std::size_t frames = 0, boxes = 0;
    forEachFrame(video, images, {}, max_frames, [&](const std::string& frame, const cv::Mat& img) {
      for (const auto& b : detector->detect(img)) {
        csv << frame << ',' << b.box.x << ',' << b.box.y << ',' << b.box.width << ',' << b.box.height << ','
            << b.confidence << '\n';
        ++boxes;
      }
      ++frames;
    });
    std::printf("%zu frames, %zu boxes -> %s\n", frames, boxes, out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "detect_people: %s\n", e.what());
    return 1;
  }
  return 0;
}
