#include "picker_localisation/sensors_vision/person_box_detector.h"

#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>

namespace picker_localisation {
namespace sensors {

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

HogPersonDetector::HogPersonDetector(HogOptions options) : options_(options), impl_(std::make_shared<Impl>()) {
  impl_->hog.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
}

std::vector<PersonBox> HogPersonDetector::detect(const cv::Mat& bgr) const {
  std::vector<PersonBox> out;
  if (bgr.empty()) return out;
  cv::Mat img = bgr;
  double factor = options_.resize > 0.0 ? options_.resize : 1.0;
  if (options_.max_width > 0 && bgr.cols * factor > options_.max_width)
    factor = static_cast<double>(options_.max_width) / bgr.cols;
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
  return std::atan(2.0 * dx * std::tan(0.5 * horizontal_fov) / width);  // seed 004 Eq. 1
}

}  // namespace sensors
}  // namespace picker_localisation
