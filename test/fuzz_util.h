// Seeded random inputs shared by the fuzz tests (test_fuzz_inputs: the parsers and front-ends in process;
// test_fuzz_nodes: the running nodes through their topics and services). Seeded: a failure reproduces.
#pragma once

#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace fuzz {

// Random values a broken driver or a hostile publisher may send.
struct Wild {
  std::mt19937_64 rng;
  explicit Wild(std::uint64_t seed) : rng(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  std::size_t index(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); }
  bool chance(double p) { return uniform(0.0, 1.0) < p; }
  // Mostly plausible (around `typical`, spread `spread`), sometimes pathological.
  double value(double typical, double spread) {
    switch (index(12)) {
      case 0:
        return std::numeric_limits<double>::quiet_NaN();
      case 1:
        return std::numeric_limits<double>::infinity();
      case 2:
        return -std::numeric_limits<double>::infinity();
      case 3:
        return 0.0;
      case 4:
        return uniform(-1e300, 1e300);
      case 5:
        return -typical - spread;
      case 6:
        return std::numeric_limits<double>::denorm_min();
      default:
        return typical + spread * std::normal_distribution<double>(0.0, 1.0)(rng);
    }
  }
  std::size_t size(std::size_t typical) {  // 0, typical-ish, or large
    switch (index(6)) {
      case 0:
        return 0;
      case 1:
        return 1;
      case 2:
        return index(20 * typical + 1);
      default:
        return index(2 * typical + 1);
    }
  }
  std::string name(const std::vector<std::string>& known) {
    if (!known.empty() && chance(0.7)) return known[index(known.size())];
    std::string s(size(8), 'x');
    for (char& c : s) c = static_cast<char>(index(256));
    return s;
  }
};

// The tmap2 text `original` mutated (one to four erasures, inserted YAML tokens, random bytes, truncations),
// or every tenth call (i % 10 == 9) random bytes alone: what a broken map manager or a hostile node may send.
inline std::string mutantMapText(const std::string& original, int i, Wild& w) {
  static const std::vector<std::string> tokens = {":",
                                                  "-",
                                                  "{",
                                                  "}",
                                                  "[",
                                                  "]",
                                                  "'",
                                                  "\"",
                                                  "&a",
                                                  "*a",
                                                  "!!binary",
                                                  "\n",
                                                  "  ",
                                                  "nodes:",
                                                  "edges:",
                                                  "node:",
                                                  ".nan",
                                                  "-.inf",
                                                  "1e999",
                                                  "~",
                                                  "\t",
                                                  "<<: *a",
                                                  "%YAML 1.2\n---\n",
                                                  std::string(1, '\0')};
  std::string text;
  if (i % 10 == 9) {
    text.resize(w.size(2000));
    for (char& c : text) c = static_cast<char>(w.index(256));
    return text;
  }
  text = original;
  for (int k = static_cast<int>(w.index(4)); k >= 0; --k) {
    const std::size_t at = w.index(text.size());
    switch (w.index(4)) {
      case 0:
        text.erase(at, w.index(200));
        break;
      case 1:
        text.insert(at, tokens[w.index(tokens.size())]);
        break;
      case 2:
        text[at] = static_cast<char>(w.index(256));
        break;
      default:
        text.resize(at);
        break;
    }
  }
  return text;
}

}  // namespace fuzz
