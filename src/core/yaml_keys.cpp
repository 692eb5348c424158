#include "picker_localisation/core/yaml_keys.h"

#include <sstream>

#include <algorithm>

namespace picker_localisation {
namespace core {

namespace {
std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}
}  // namespace

std::string closestKey(const std::string& key, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_d = static_cast<std::size_t>(-1);
  for (const auto& k : known) {
    const std::size_t d = editDistance(key, k);
    if (d < best_d) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

std::vector<std::string> unknownKeys(const YAML::Node& node, const std::vector<std::string>& known,
                                     const std::string& component) {
  std::vector<std::string> out;
  if (!node || !node.IsMap()) return out;
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    const std::string near = closestKey(key, known);
    out.push_back(component + ": unknown key '" + key + "'" +
                  (near.empty() ? "" : " (did you mean '" + near + "'?)"));
  }
  return out;
}

std::string badValue(const char* key, double value, const char* rule) {
  std::ostringstream s;
  s << key << " = " << value << ": must be " << rule;
  return s.str();
}

}  // namespace core
}  // namespace picker_localisation
