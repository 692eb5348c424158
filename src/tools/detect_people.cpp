// Offline person boxes on a video or a folder of images:
//   detect_people --video FILE | --images DIR --out FILE.csv [--resize F] [--onnx MODEL.onnx] [--max-frames N]
// CSV: frame,x,y,width,height,confidence (frame: the image's file name, or the video frame index; x, y: top-left
// corner in pixels of the original image). HOG people detector unless --onnx is given.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "picker_localisation/sensors_vision/person_box_detector.h"

using namespace picker_localisation::vision;

int main(int argc, char** argv) {
  std::string video, images, out, onnx;
  std::size_t max_frames = 0;  // 0: all
  HogOptions hog;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--video") video = argv[i + 1];
    else if (a == "--images") images = argv[i + 1];
    else if (a == "--out") out = argv[i + 1];
    else if (a == "--resize") hog.resize = std::stod(argv[i + 1]);
    else if (a == "--onnx") onnx = argv[i + 1];
    else if (a == "--max-frames") max_frames = std::stoul(argv[i + 1]);
    else {
      std::fprintf(stderr, "detect_people: unknown option %s\n", a.c_str());
      return 2;
    }
  }
  if (out.empty() || video.empty() == images.empty()) {
    std::fprintf(stderr, "usage: detect_people --video FILE|--images DIR --out FILE.csv [--resize F] [--onnx M] [--max-frames N]\n");
    return 2;
  }
  try {
    std::unique_ptr<PersonBoxDetector> detector;
    if (onnx.empty())
      detector = std::make_unique<HogPersonDetector>(hog);
    else
      detector = std::make_unique<OnnxPersonDetector>(OnnxOptions{onnx});
    std::ofstream csv(out);
    if (!csv) throw std::runtime_error("cannot write " + out);
    csv << "frame,x,y,width,height,confidence\n";
    std::size_t frames = 0, boxes = 0;
    auto write = [&](const std::string& frame, const cv::Mat& img) {
      for (const auto& b : detector->detect(img)) {
        csv << frame << ',' << b.box.x << ',' << b.box.y << ',' << b.box.width << ',' << b.box.height << ','
            << b.confidence << '\n';
        ++boxes;
      }
      ++frames;
    };
    if (!video.empty()) {
      cv::VideoCapture cap(video);
      if (!cap.isOpened()) throw std::runtime_error("cannot open video " + video);
      cv::Mat frame;
      for (int index = 0; (max_frames == 0 || frames < max_frames) && cap.read(frame); ++index)
        write(std::to_string(index), frame);
    } else {
      std::vector<std::filesystem::path> files;
      for (const auto& e : std::filesystem::directory_iterator(images))
        if (e.is_regular_file()) files.push_back(e.path());
      std::sort(files.begin(), files.end());
      for (const auto& f : files) {
        if (max_frames > 0 && frames >= max_frames) break;
        const cv::Mat img = cv::imread(f.string(), cv::IMREAD_COLOR);
        if (img.empty()) continue;  // not an image
        write(f.filename().string(), img);
      }
    }
    std::printf("%zu frames, %zu boxes -> %s\n", frames, boxes, out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "detect_people: %s\n", e.what());
    return 1;
  }
  return 0;
}
