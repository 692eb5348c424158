// Monocular person detection (OpenCV HOG people detector by default, optional ONNX model through cv::dnn) and
// the bearing of a box from the camera intrinsics (seed 004 Eq. 1). ROS-free.
#pragma once

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace picker_localisation {
namespace sensors {

struct PersonBox {
  cv::Rect box;             // pixels of the original image
  double confidence = 0.0;  // [0, 1]
};

class PersonBoxDetector {
 public:
  virtual ~PersonBoxDetector() = default;
  virtual std::vector<PersonBox> detect(const cv::Mat& bgr) const = 0;
};

struct HogOptions {
  double scale = 1.05;            // detectMultiScale pyramid step
  double hit_threshold = 0.0;     // SVM margin threshold
  double resize = 1.0;            // image resize factor before detection (boxes are scaled back); > 1 finds people
                                  // smaller than the 64 x 128 px HOG window
  int max_width = 1280;           // the resized image is capped at this width, px
  double min_confidence = 0.3;    // boxes below this confidence are dropped
  double nms_iou = 0.4;           // non-maximum suppression overlap
  double confidence_scale = 1.0;  // confidence = 1 - exp(-weight / scale) for the SVM weight
};

// cv::HOGDescriptor with getDefaultPeopleDetector() (no weights to download).
class HogPersonDetector : public PersonBoxDetector {
 public:
  explicit HogPersonDetector(HogOptions options = {});
  std::vector<PersonBox> detect(const cv::Mat& bgr) const override;

 private:
  HogOptions options_;
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

struct OnnxOptions {
  std::string model_path;       // user-supplied ONNX file
  int input_width = 300, input_height = 300;
  double scale = 1.0 / 127.5;   // blob = (pixel - mean) * scale
  double mean = 127.5;
  bool swap_rb = true;
  int person_class = 1;         // class id of "person" in the model's labels
  double min_confidence = 0.5;
  double nms_iou = 0.4;
};

// An SSD-style detector whose output is [1, 1, N, 7] rows (image, class, score, x1, y1, x2, y2), coordinates
// normalised to [0, 1] (the layout of OpenCV's DetectionOutput layer, e.g. MobileNet-SSD exports). The
// constructor throws std::runtime_error when the model cannot be read.
class OnnxPersonDetector : public PersonBoxDetector {
 public:
  explicit OnnxPersonDetector(OnnxOptions options);
  std::vector<PersonBox> detect(const cv::Mat& bgr) const override;

 private:
  OnnxOptions options_;
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

// Pinhole intrinsics along the image's horizontal axis (from sensor_msgs/CameraInfo K: fx = K[0], cx = K[2]).
struct CameraIntrinsics {
  double fx = 0.0;
  double cx = 0.0;
  int width = 0;
};

// Seed 004 Eq. 1: theta = atan(2 dx tan(f_w / 2) / w), dx the horizontal offset of the pixel column from the
// image centre. With the pinhole model tan(f_w / 2) = (w / 2) / f_x and the centre at the principal point c_x,
// this is theta = atan((c_x - u) / f_x). Sign: REP 103 body convention, positive to the LEFT (u < c_x).
double bearingFromColumn(double u, const CameraIntrinsics& k);
double bearingFromBox(const cv::Rect& box, const CameraIntrinsics& k);  // bearing of the box's centre column
// Eq. 1 in its field-of-view form (no principal point: the image centre w/2 is used).
double bearingFromColumnFov(double u, double horizontal_fov, int width);

// Greedy non-maximum suppression: keeps the most confident box of each group overlapping more than iou.
std::vector<PersonBox> suppressOverlaps(std::vector<PersonBox> boxes, double iou);

}  // namespace sensors
}  // namespace picker_localisation
