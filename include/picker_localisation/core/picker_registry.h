// The pickers a deployment tracks, from config/pickers.yaml. ROS-free.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace picker_localisation {
namespace core {

struct PickerConfig {
  std::string id;                      // unique; names the tracker, topics and frames (/pickers/<id>/...)
  std::string gnss_topic;              // sensor_msgs/NavSatFix topic of the picker's phone / IoT unit ("" none)
  std::vector<std::string> rfid_tags;  // RFID tag ids worn by the picker
  std::string uwb_tag;                 // UWB tag id worn by the picker ("" none)
  std::string tpf_overrides;           // YAML mapping of config/tpf.yaml keys for this picker's filter ("" none)
};

// "" when `id` can name a picker (it becomes a ROS name component: /pickers/<id>/belief, a tf frame):
// a letter first, then letters, digits and '_', at most kMaxPickerIdLength characters; else why not.
constexpr std::size_t kMaxPickerIdLength = 64;
std::string pickerIdProblem(const std::string& id);
// `text` cut to `max_chars` with its length noted, for log lines and replies that quote what a caller sent.
std::string clippedForLog(const std::string& text, std::size_t max_chars = 80);

// Format:
//   pickers:
//     - id: picker_1
//       gnss_topic: /pickers/picker_1/fix
//       rfid_tags: [tag_0001]
//       uwb_tag: uwb_0001
//       tpf: {num_particles: 2000}   # optional overrides of config/tpf.yaml for this picker
// Throws std::runtime_error with one line naming the file, the entry and the field on a bad file
// (missing, invalid or duplicate id, an empty tag or one claimed by two pickers, a GNSS topic of two pickers,
// wrong types).
class PickerRegistry {
 public:
  static PickerRegistry load(const std::string& path);
  static PickerRegistry parse(const std::string& yaml_text, const std::string& source = "<memory>");
  explicit PickerRegistry(std::vector<PickerConfig> pickers = {}, const std::string& source = "<memory>");

  const std::vector<PickerConfig>& pickers() const { return pickers_; }
  std::size_t size() const { return pickers_.size(); }
  const PickerConfig* find(const std::string& id) const;
  // Picker wearing the RFID / UWB tag; nullopt for an unknown tag.
  std::optional<std::string> pickerForRfidTag(const std::string& tag) const;
  std::optional<std::string> pickerForUwbTag(const std::string& tag) const;
  std::vector<std::string> ids() const;

  // Run-time changes (tpf_tracker's add / remove services). add() throws std::runtime_error, changing nothing,
  // when the picker could not be in a registry with the others (the rules above); remove() is false for an
  // unknown id.
  void add(PickerConfig picker);
  bool remove(const std::string& id);

 private:
  std::vector<PickerConfig> pickers_;
};

}  // namespace core
}  // namespace picker_localisation
