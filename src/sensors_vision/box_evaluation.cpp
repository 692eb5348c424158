#include "picker_localisation/sensors_vision/box_evaluation.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace picker_localisation {
namespace vision {

std::vector<LabelledPerson> readPeopleLabels(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read labels " + path);
  std::vector<LabelledPerson> labels;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty() || line[0] == '#' || line.rfind("frame,", 0) == 0) continue;
    std::stringstream row(line);
    std::vector<std::string> cells;
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    const auto bad = [&](const std::string& why) {
      return std::runtime_error(path + ":" + std::to_string(number) + ": " + why +
                                " (expected frame,x1,y1,x2,y2,person|ignore): " + line);
    };
    if (cells.size() != 6) throw bad(std::to_string(cells.size()) + " fields");
    int corner[4];
    try {
      for (int i = 0; i < 4; ++i) {
        std::size_t used = 0;
        corner[i] = std::stoi(cells[i + 1], &used);
        if (used != cells[i + 1].size()) throw std::invalid_argument(cells[i + 1]);
      }
    } catch (const std::exception&) {
      throw bad("a corner is not an integer");
    }
    if (corner[2] <= corner[0] || corner[3] <= corner[1]) throw bad("x2 <= x1 or y2 <= y1");
    if (cells[5] != "person" && cells[5] != "ignore") throw bad("kind '" + cells[5] + "'");
    labels.push_back({cells[0], cv::Rect(cv::Point(corner[0], corner[1]), cv::Point(corner[2], corner[3])),
                      cells[5] == "ignore"});
  }
  return labels;
}

std::map<std::string, std::vector<LabelledPerson>> labelsByFrame(const std::vector<LabelledPerson>& labels) {
  std::map<std::string, std::vector<LabelledPerson>> by_frame;
  for (const auto& l : labels) by_frame[l.frame].push_back(l);
  return by_frame;
}

bool boxMatchesPerson(const cv::Rect& detection, const cv::Rect& person) {
  const cv::Point centre(person.x + person.width / 2, person.y + person.height / 2);
  const double ratio = static_cast<double>(detection.height) / person.height;
  return detection.contains(centre) && ratio >= 0.6 && ratio <= 2.2;
}

void BoxScore::add(const BoxScore& o) {
  frames += o.frames;
  people += o.people;
  found += o.found;
  detections += o.detections;
  seconds += o.seconds;
}

BoxScore scoreFrame(const std::vector<PersonBox>& detections, const std::vector<LabelledPerson>& labels) {
  BoxScore s;
  s.frames = 1;
  for (const auto& l : labels) s.people += l.ignore ? 0 : 1;
  std::vector<const PersonBox*> order;
  for (const auto& d : detections) order.push_back(&d);
  std::stable_sort(order.begin(), order.end(),
                   [](const PersonBox* a, const PersonBox* b) { return a->confidence > b->confidence; });
  std::vector<char> taken(labels.size(), 0);
  for (const PersonBox* d : order) {
    int best = -1;
    double best_overlap = -1.0;
    bool on_ignored = false;
    for (std::size_t i = 0; i < labels.size(); ++i) {
      if (!boxMatchesPerson(d->box, labels[i].box)) continue;
      if (labels[i].ignore) {
        on_ignored = true;
        continue;
      }
      if (taken[i]) continue;
      const double overlap = (d->box & labels[i].box).area();
      if (overlap > best_overlap) {
        best_overlap = overlap;
        best = static_cast<int>(i);
      }
    }
    if (best >= 0) {
      taken[best] = 1;
      ++s.found;
      ++s.detections;
    } else if (!on_ignored) {
      ++s.detections;
    }
  }
  return s;
}

}  // namespace vision
}  // namespace picker_localisation
