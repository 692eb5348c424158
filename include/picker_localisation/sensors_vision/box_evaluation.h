// Scoring person boxes against hand labels (recall, precision, false boxes and time per frame), used by the
// `detect_people --labels` tool that measures the camera options table and by the real-data test. ROS-free.
#pragma once

#include <opencv2/core.hpp>

#include <map>
#include <string>
#include <vector>

#include "picker_localisation/sensors_vision/person_box_detector.h"

namespace picker_localisation {
namespace vision {

// One labelled person of one frame (frame: the video frame index as text, or the image's file name). An
// `ignore` label marks a person too small or too hidden to demand: a detection on it is neither a hit nor a
// false box.
struct LabelledPerson {
  std::string frame;
  cv::Rect box;
  bool ignore = false;
};

// Reads `frame,x1,y1,x2,y2,kind` rows (kind `person` or `ignore`; `#` comment lines and the header skipped).
// Throws std::runtime_error naming the file and line of a malformed row.
std::vector<LabelledPerson> readPeopleLabels(const std::string& path);
std::map<std::string, std::vector<LabelledPerson>> labelsByFrame(const std::vector<LabelledPerson>& labels);

// A detection matches a person when it contains the person's centre and its height is 0.6-2.2 times theirs
// (HOG boxes carry a margin around the body).
bool boxMatchesPerson(const cv::Rect& detection, const cv::Rect& person);

struct BoxScore {
  std::size_t frames = 0;
  std::size_t people = 0;      // labelled people (ignore labels excluded)
  std::size_t found = 0;       // people matched by a detection (one detection per person)
  std::size_t detections = 0;  // detections counted (those on ignore labels excluded)
  double seconds = 0.0;        // detection time, summed over frames (filled by the caller)

  double recall() const { return people ? static_cast<double>(found) / people : 0.0; }
  double precision() const { return detections ? static_cast<double>(found) / detections : 1.0; }
  double falsePerFrame() const { return frames ? static_cast<double>(detections - found) / frames : 0.0; }
  double msPerFrame() const { return frames ? 1e3 * seconds / frames : 0.0; }
  void add(const BoxScore& other);
};

// Scores one frame's detections: in decreasing confidence, each detection takes the unmatched person it
// matches with the largest overlap; a detection matching no free person but an ignore label is not counted;
// any other is a false box (a second box on one person included).
BoxScore scoreFrame(const std::vector<PersonBox>& detections,
                    const std::vector<LabelledPerson>& frame_labels);

}  // namespace vision
}  // namespace picker_localisation
