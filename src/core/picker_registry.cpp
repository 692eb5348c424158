#include "picker_localisation/core/picker_registry.h"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace picker_localisation {
namespace core {

namespace {
[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::runtime_error(source + ": " + what);
}
}  // namespace

std::string clippedForLog(const std::string& text, std::size_t max_chars) {
  if (text.size() <= max_chars) return text;
  return text.substr(0, max_chars) + "...(" + std::to_string(text.size()) + " chars)";
}

std::string pickerIdProblem(const std::string& id) {
  if (id.empty()) return "the id is empty";
  if (id.size() > kMaxPickerIdLength)
    return "id '" + clippedForLog(id) + "' is longer than " + std::to_string(kMaxPickerIdLength) +
           " characters";
  if (!std::isalpha(static_cast<unsigned char>(id[0])))
    return "id '" + id + "' must start with a letter (it names topics /pickers/<id>/...)";
  for (char c : id)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
      return "id '" + id + "' may hold only letters, digits and '_' (it names topics /pickers/<id>/...)";
  return "";
}

PickerRegistry::PickerRegistry(std::vector<PickerConfig> pickers, const std::string& source)
    : pickers_(std::move(pickers)) {
  std::unordered_map<std::string, std::string> ids, rfid, uwb, gnss;
  for (const PickerConfig& p : pickers_) {
    const std::string id_problem = pickerIdProblem(p.id);
    if (!id_problem.empty()) fail(source, id_problem + " (field 'id')");
    if (!ids.emplace(p.id, p.id).second) fail(source, "duplicate picker id '" + p.id + "' (field 'id')");
    for (const std::string& t : p.rfid_tags) {
      if (t.empty()) fail(source, "picker '" + p.id + "' has an empty RFID tag (field 'rfid_tags')");
      auto [it, fresh] = rfid.emplace(t, p.id);
      if (!fresh)
        fail(source, "RFID tag '" + clippedForLog(t) + "' belongs to both '" + it->second + "' and '" + p.id +
                         "' (field 'rfid_tags')");
    }
    if (!p.uwb_tag.empty()) {
      auto [it, fresh] = uwb.emplace(p.uwb_tag, p.id);
      if (!fresh)
        fail(source, "UWB tag '" + clippedForLog(p.uwb_tag) + "' belongs to both '" + it->second + "' and '" +
                         p.id + "' (field 'uwb_tag')");
    }
    // One device per picker: two pickers on one fix topic would each take the other's fixes as their own.
    if (!p.gnss_topic.empty()) {
      auto [it, fresh] = gnss.emplace(p.gnss_topic, p.id);
      if (!fresh)
        fail(source, "GNSS topic '" + clippedForLog(p.gnss_topic) + "' belongs to both '" + it->second +
                         "' and '" + p.id + "' (field 'gnss_topic')");
    }
  }
}

PickerRegistry PickerRegistry::parse(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    fail(source, "YAML syntax error at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root || !root.IsMap() || !root["pickers"] || !root["pickers"].IsSequence())
    fail(source, "expected a mapping with a 'pickers' list");
  std::vector<PickerConfig> out;
  std::size_t i = 0;
  for (const YAML::Node& e : root["pickers"]) {
    const std::string where = "pickers[" + std::to_string(i++) + "]";
    if (!e.IsMap()) fail(source, where + " is not a mapping");
    PickerConfig p;
    try {
      if (!e["id"] || !e["id"].IsScalar()) fail(source, where + ": missing 'id'");
      p.id = e["id"].as<std::string>();
      if (e["gnss_topic"] && !e["gnss_topic"].IsNull()) p.gnss_topic = e["gnss_topic"].as<std::string>();
      if (e["uwb_tag"] && !e["uwb_tag"].IsNull()) p.uwb_tag = e["uwb_tag"].as<std::string>();
      if (e["tpf"] && !e["tpf"].IsNull()) {
        if (!e["tpf"].IsMap()) fail(source, where + " ('" + p.id + "'): 'tpf' must be a mapping of config/tpf.yaml keys");
        p.tpf_overrides = YAML::Dump(e["tpf"]);
      }
      if (e["rfid_tags"] && !e["rfid_tags"].IsNull()) {
        if (e["rfid_tags"].IsScalar())
          p.rfid_tags.push_back(e["rfid_tags"].as<std::string>());
        else
          p.rfid_tags = e["rfid_tags"].as<std::vector<std::string>>();
      }
    } catch (const YAML::Exception& ex) {
      fail(source, where + " ('" + p.id + "'): wrong type: " + ex.msg);
    }
    out.push_back(std::move(p));
  }
  return PickerRegistry(std::move(out), source);
}

PickerRegistry PickerRegistry::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot open the file for reading");
  std::ostringstream s;
  s << in.rdbuf();
  return parse(s.str(), path);
}

const PickerConfig* PickerRegistry::find(const std::string& id) const {
  for (const PickerConfig& p : pickers_)
    if (p.id == id) return &p;
  return nullptr;
}

std::optional<std::string> PickerRegistry::pickerForRfidTag(const std::string& tag) const {
  for (const PickerConfig& p : pickers_)
    for (const std::string& t : p.rfid_tags)
      if (t == tag) return p.id;
  return std::nullopt;
}

std::optional<std::string> PickerRegistry::pickerForUwbTag(const std::string& tag) const {
  for (const PickerConfig& p : pickers_)
    if (!p.uwb_tag.empty() && p.uwb_tag == tag) return p.id;
  return std::nullopt;
}

void PickerRegistry::add(PickerConfig picker) {
  const std::string source = "picker '" + clippedForLog(picker.id) + "'";
  std::vector<PickerConfig> all = pickers_;
  all.push_back(std::move(picker));
  *this = PickerRegistry(std::move(all), source);
}

bool PickerRegistry::remove(const std::string& id) {
  for (auto it = pickers_.begin(); it != pickers_.end(); ++it)
    if (it->id == id) {
      pickers_.erase(it);
      return true;
    }
  return false;
}

std::vector<std::string> PickerRegistry::ids() const {
  std::vector<std::string> out;
  for (const PickerConfig& p : pickers_) out.push_back(p.id);
  return out;
}

}  // namespace core
}  // namespace picker_localisation
