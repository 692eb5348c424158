#include "picker_localisation/sensors_vision/person_box_detector.h"

#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>

#include "picker_localisation/core/yaml_file.h"
#include "picker_localisation/core/yaml_keys.h"

namespace picker_localisation {
namespace vision {

std::vector<PersonBox> suppressOverlaps(std::vector<PersonBox> boxes, double iou) {
  std::stable_sort(boxes.begin(), boxes.end(),
                   [](const PersonBox& a, const PersonBox& b) { return a.confidence > b.confidence; });
  std::vector<PersonBox> kept;
  for (const auto& b : boxes) {
    bool overlaps = false;
    for (const auto& k : kept) {
      const double inter = (b.box & k.box).area();
      const double uni = b.box.area() + k.box.area() - inter;
      // Also drop a box that lies mostly inside a kept one (HOG often fires on a person's upper body).
      const double inside = b.box.area() > 0 ? inter / b.box.area() : 0.0;
      if ((uni > 0.0 && inter / uni > iou) || inside > 0.8) {
        overlaps = true;
        break;
      }
    }
    if (!overlaps) kept.push_back(b);
  }
  return kept;
}

// ---------------------------------------------------------------------------------------------- HOG
struct HogPersonDetector::Impl {
  cv::HOGDescriptor hog;
  std::mutex mutex;  // detectMultiScale is const but keep one user at a time for its internal buffers
};

const std::vector<std::string>& CameraDetectorOptions::yamlKeys() {
  static const std::vector<std::string> keys{"onnx_model",       "hog_model",         "resize",
                                             "hit_threshold",    "min_confidence",    "scale",
                                             "onnx_input_width", "onnx_input_height", "onnx_person_class",
                                             "max_rate",         "max_age",           "max_future_stamp",
                                             "horizontal_fov",   "bearing_frame",     "robot_id"};
  return keys;
}

CameraDetectorOptions CameraDetectorOptions::fromYaml(const YAML::Node& y, std::vector<std::string>* unknown) {
  CameraDetectorOptions o;
  if (!y || !y.IsMap()) return o;
  const std::string c = "camera_detector";
  core::readOption(y, c, "onnx_model", o.onnx_model);
  core::readOption(y, c, "hog_model", o.hog.model);
  core::readOption(y, c, "resize", o.hog.resize);
  core::readOption(y, c, "hit_threshold", o.hog.hit_threshold);
  core::readOption(y, c, "scale", o.hog.scale);
  core::readOption(y, c, "min_confidence", o.hog.min_confidence);
  core::readOption(y, c, "min_confidence", o.onnx.min_confidence);
  core::readOption(y, c, "onnx_input_width", o.onnx.input_width);
  core::readOption(y, c, "onnx_input_height", o.onnx.input_height);
  core::readOption(y, c, "onnx_person_class", o.onnx.person_class);
  core::readOption(y, c, "max_rate", o.max_rate);
  core::readOption(y, c, "max_age", o.max_age);
  core::readOption(y, c, "max_future_stamp", o.max_future_stamp);
  core::readOption(y, c, "horizontal_fov", o.horizontal_fov);
  core::readOption(y, c, "bearing_frame", o.bearing_frame);
  core::readOption(y, c, "robot_id", o.robot_id);
  o.onnx.model_path = o.onnx_model;
  return core::checkOptions(o, y, yamlKeys(), c, unknown);
}

CameraDetectorOptions CameraDetectorOptions::fromYamlFile(const std::string& path, std::vector<std::string>* unknown) {
  return core::parseYamlFile(path, [&](const YAML::Node& root) { return fromYaml(root["camera_detector"], unknown); });
}

std::string CameraDetectorOptions::validate() const {
  const auto bad = core::badValue;
  if (hog.model != "default" && hog.model != "daimler")
    return "hog_model = " + hog.model + ": must be default or daimler";
  if (!(hog.resize > 0.0 && hog.resize <= 4.0)) return bad("resize", hog.resize, "in (0, 4]");
  if (!(hog.scale > 1.0 && hog.scale <= 2.0)) return bad("scale", hog.scale, "in (1, 2]");
  if (!std::isfinite(hog.hit_threshold)) return bad("hit_threshold", hog.hit_threshold, "finite");
  const double confidence = onnx_model.empty() ? hog.min_confidence : onnx.min_confidence;
  if (!(confidence >= 0.0 && confidence <= 1.0)) return bad("min_confidence", confidence, "in [0, 1]");
  if (onnx.input_width <= 0) return bad("onnx_input_width", onnx.input_width, "> 0");
  if (onnx.input_height <= 0) return bad("onnx_input_height", onnx.input_height, "> 0");
  if (!(max_rate >= 0.0) || !std::isfinite(max_rate)) return bad("max_rate", max_rate, "finite and >= 0 (0: every frame)");
  if (!(max_age >= 0.0)) return bad("max_age", max_age, ">= 0 (0: any age)");
  if (!(max_future_stamp >= 0.0)) return bad("max_future_stamp", max_future_stamp, ">= 0");
  if (!(horizontal_fov >= 0.0 && horizontal_fov < 2.0 * M_PI)) return bad("horizontal_fov", horizontal_fov, "in [0, 2 pi)");
  return "";
}

std::unique_ptr<PersonBoxDetector> CameraDetectorOptions::makeDetector() const {
  if (onnx_model.empty()) return std::make_unique<HogPersonDetector>(hog);
  return std::make_unique<OnnxPersonDetector>(onnx);
}

HogPersonDetector::HogPersonDetector(HogOptions options) : options_(options), impl_(std::make_shared<Impl>()) {
  if (options_.model == "default") {
    impl_->hog.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
  } else if (options_.model == "daimler") {
    // The Daimler SVM's descriptor: 48 x 96 window, 16 px blocks, 8 px stride and cells, 9 bins.
    impl_->hog = cv::HOGDescriptor(cv::Size(48, 96), cv::Size(16, 16), cv::Size(8, 8), cv::Size(8, 8), 9);
    impl_->hog.setSVMDetector(cv::HOGDescriptor::getDaimlerPeopleDetector());
  } else {
    throw std::invalid_argument("HogPersonDetector: unknown model '" + options_.model + "' (default or daimler)");
  }
}

std::vector<PersonBox> HogPersonDetector::detect(const cv::Mat& bgr) const {
  std::vector<PersonBox> out;
  if (bgr.empty()) return out;
  cv::Mat img = bgr;
  const double factor = options_.resize > 0.0 ? options_.resize : 1.0;
  if (std::abs(factor - 1.0) > 1e-9)
    cv::resize(bgr, img, cv::Size(), factor, factor, factor < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
  // An image smaller than the HOG window holds no person; OpenCV 4.6 crashes on it (bug #8793), so it is not
  // passed on. Non-8-bit or non-3-channel input is refused the same way.
  const cv::Size window = impl_->hog.winSize;
  if (img.cols < window.width || img.rows < window.height || img.type() != CV_8UC3) return out;
  std::vector<cv::Rect> rects;
  std::vector<double> weights;
  try {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->hog.detectMultiScale(img, rects, weights, options_.hit_threshold, cv::Size(8, 8), cv::Size(),
                                options_.scale, 2.0, false);
  } catch (const cv::Exception&) {
    return out;  // OpenCV refused the image: no detections
  }
  for (std::size_t i = 0; i < rects.size(); ++i) {
    PersonBox b;
    // The SVM margin is unbounded; map it to [0, 1) monotonically.
    const double w = i < weights.size() ? weights[i] : 0.0;
    b.confidence = 1.0 - std::exp(-std::max(0.0, w) / options_.confidence_scale);
    if (b.confidence < options_.min_confidence) continue;
    cv::Rect r(cvRound(rects[i].x / factor), cvRound(rects[i].y / factor), cvRound(rects[i].width / factor),
               cvRound(rects[i].height / factor));
    b.box = r & cv::Rect(0, 0, bgr.cols, bgr.rows);
    if (b.box.area() > 0) out.push_back(b);
  }
  return suppressOverlaps(std::move(out), options_.nms_iou);
}

// ---------------------------------------------------------------------------------------------- ONNX
struct OnnxPersonDetector::Impl {
  cv::dnn::Net net;
  std::mutex mutex;
};

OnnxPersonDetector::OnnxPersonDetector(OnnxOptions options) : options_(std::move(options)), impl_(std::make_shared<Impl>()) {
  try {
    impl_->net = cv::dnn::readNetFromONNX(options_.model_path);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("OnnxPersonDetector: cannot read " + options_.model_path + ": " + e.what());
  }
  if (impl_->net.empty()) throw std::runtime_error("OnnxPersonDetector: empty network " + options_.model_path);
  // One pass on a grey image now, so a model of the wrong input size or output layout fails at start-up with
  // its shape named, not at the first camera frame.
  cv::Mat result;
  try {
    impl_->net.setInput(cv::Mat(std::vector<int>{1, 3, options_.input_height, options_.input_width}, CV_32F,
                                cv::Scalar(0.0)));
    result = impl_->net.forward();
  } catch (const cv::Exception& e) {
    throw std::runtime_error("OnnxPersonDetector: " + options_.model_path + " does not run on a 1 x 3 x " +
                             std::to_string(options_.input_height) + " x " +
                             std::to_string(options_.input_width) +
                             " input (onnx_input_height / onnx_input_width): " + e.what());
  }
  checkOutputShape(result);
}

void OnnxPersonDetector::checkOutputShape(const cv::Mat& result) const {
  if (result.dims >= 2 && result.size[result.dims - 1] == 7) return;
  std::string shape;
  for (int d = 0; d < result.dims; ++d) shape += (d ? " x " : "") + std::to_string(result.size[d]);
  throw std::runtime_error(
      "OnnxPersonDetector: " + options_.model_path + " outputs [" + shape +
      "], expected rows of 7 (image, class, score, x1, y1, x2, y2), e.g. [1 x 1 x N x 7] as "
      "OpenCV's DetectionOutput layer (an SSD export)");
}

std::vector<PersonBox> OnnxPersonDetector::detect(const cv::Mat& bgr) const {
  std::vector<PersonBox> out;
  if (bgr.empty()) return out;
  const cv::Mat blob =
      cv::dnn::blobFromImage(bgr, options_.scale, cv::Size(options_.input_width, options_.input_height),
                             cv::Scalar::all(options_.mean), options_.swap_rb, false);
  cv::Mat result;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->net.setInput(blob);
    result = impl_->net.forward();
  }
  checkOutputShape(result);
  const cv::Mat rows(static_cast<int>(result.total() / 7), 7, CV_32F, result.ptr<float>());
  for (int i = 0; i < rows.rows; ++i) {
    const float* r = rows.ptr<float>(i);
    if (static_cast<int>(r[1]) != options_.person_class || r[2] < options_.min_confidence) continue;
    const int x1 = cvRound(r[3] * bgr.cols), y1 = cvRound(r[4] * bgr.rows);
    const int x2 = cvRound(r[5] * bgr.cols), y2 = cvRound(r[6] * bgr.rows);
    PersonBox b;
    b.box = cv::Rect(cv::Point(x1, y1), cv::Point(x2, y2)) & cv::Rect(0, 0, bgr.cols, bgr.rows);
    b.confidence = std::clamp(static_cast<double>(r[2]), 0.0, 1.0);
    if (b.box.area() > 0) out.push_back(b);
  }
  return suppressOverlaps(std::move(out), options_.nms_iou);
}

// ---------------------------------------------------------------------------------------------- bearing
double bearingFromColumn(double u, const CameraIntrinsics& k) {
  if (!(k.fx > 0.0)) throw std::invalid_argument("bearingFromColumn: fx must be > 0");
  return std::atan((k.cx - u) / k.fx);
}

double bearingFromBox(const cv::Rect& box, const CameraIntrinsics& k) {
  return bearingFromColumn(box.x + 0.5 * box.width, k);
}

double bearingFromColumnFov(double u, double horizontal_fov, int width) {
  if (width <= 0 || !(horizontal_fov > 0.0)) throw std::invalid_argument("bearingFromColumnFov: bad fov/width");
  const double dx = 0.5 * width - u;  // positive left of the centre
  return std::atan(2.0 * dx * std::tan(0.5 * horizontal_fov) / width);  // Sarmento et al. 2024, Eq. 1
}

}  // namespace vision
}  // namespace picker_localisation
