#include "picker_localisation/nbs/choquet.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace picker_localisation {
namespace nbs {

namespace {
constexpr double kTolerance = 1e-9;

std::size_t criteriaFromSize(std::size_t size) {
  std::size_t n = 0;
  while ((std::size_t{1} << n) < size) ++n;
  if ((std::size_t{1} << n) != size || n == 0 || n > kMaxCriteria) return 0;
  return n;
}
}  // namespace

std::string FuzzyMeasure::checkMeasure(const std::vector<double>& values) {
  const std::size_t n = criteriaFromSize(values.size());
  if (n == 0)
    return "a fuzzy measure needs 2^n values for 1 <= n <= 16 criteria, got " + std::to_string(values.size());
  const std::uint32_t all = static_cast<std::uint32_t>(values.size() - 1);
  for (std::size_t s = 0; s < values.size(); ++s)
    if (!std::isfinite(values[s])) return "mu(" + std::to_string(s) + ") is not finite";
  if (std::abs(values[0]) > kTolerance) return "mu(empty set) must be 0";
  if (std::abs(values[all] - 1.0) > kTolerance) return "mu(all criteria) must be 1";
  // Monotone: adding any one criterion never lowers the value (enough for all supersets by transitivity).
  for (std::uint32_t s = 0; s <= all; ++s)
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t bit = 1u << i;
      if (!(s & bit) && values[s | bit] < values[s] - kTolerance) {
        std::ostringstream os;
        os << "not monotone: mu(" << (s | bit) << ") = " << values[s | bit] << " < mu(" << s
           << ") = " << values[s];
        return os.str();
      }
    }
  return "";
}

FuzzyMeasure FuzzyMeasure::fromSubsetValues(std::vector<double> values) {
  const std::string problem = checkMeasure(values);
  if (!problem.empty()) throw std::invalid_argument("FuzzyMeasure: " + problem);
  const std::size_t n = criteriaFromSize(values.size());
  return FuzzyMeasure(n, std::move(values));
}

FuzzyMeasure FuzzyMeasure::fromWeights(const std::vector<double>& weights,
                                       const std::vector<CriterionInteraction>& interactions) {
  const std::size_t n = weights.size();
  if (n == 0 || n > kMaxCriteria)
    throw std::invalid_argument("FuzzyMeasure: need 1 to 16 criteria, got " + std::to_string(n));
  double total = 0.0;
  for (double w : weights) {
    if (!std::isfinite(w) || w < 0.0)
      throw std::invalid_argument("FuzzyMeasure: weights must be finite and >= 0");
    total += w;
  }
  if (total <= 0.0) throw std::invalid_argument("FuzzyMeasure: the weights sum to 0");
  for (const CriterionInteraction& c : interactions) {
    if (c.a >= n || c.b >= n || c.a == c.b || !std::isfinite(c.bonus))
      throw std::invalid_argument("FuzzyMeasure: an interaction must join two different known criteria");
  }
  const std::size_t size = std::size_t{1} << n;
  std::vector<double> mu(size, 0.0);
  for (std::size_t s = 1; s < size; ++s) {
    double v = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (s & (std::size_t{1} << i)) v += weights[i] / total;
    for (const CriterionInteraction& c : interactions)
      if ((s & (std::size_t{1} << c.a)) && (s & (std::size_t{1} << c.b))) v += c.bonus;
    mu[s] = std::clamp(v, 0.0, 1.0);
  }
  // Monotone closure in increasing order of the mask: every subset s minus one element is a smaller mask, so
  // it is final when s is visited.
  for (std::size_t s = 1; s < size; ++s)
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t bit = std::size_t{1} << i;
      if (s & bit) mu[s] = std::max(mu[s], mu[s ^ bit]);
    }
  mu[0] = 0.0;
  mu[size - 1] = 1.0;
  return FuzzyMeasure(n, std::move(mu));
}

double choquetIntegral(const std::vector<double>& utilities, const FuzzyMeasure& mu) {
  const std::size_t n = mu.numCriteria();
  if (utilities.size() != n)
    throw std::invalid_argument("choquetIntegral: " + std::to_string(utilities.size()) +
                                " utilities for a measure over " + std::to_string(n) + " criteria");
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return utilities[a] < utilities[b]; });
  // A_(1) is every criterion; each step drops the criterion just integrated.
  std::uint32_t a_set = static_cast<std::uint32_t>((std::size_t{1} << n) - 1);
  double previous = 0.0, f = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const double u = utilities[order[j]];
    f += (u - previous) * mu(a_set);
    previous = u;
    a_set &= ~(1u << order[j]);
  }
  return f;
}

std::vector<double> minMaxNormalise(const std::vector<double>& raw, bool benefit) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : raw)
    if (std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  std::vector<double> out(raw.size(), 0.0);
  if (!(hi >= lo)) return out;  // nothing finite
  const double range = hi - lo;
  const bool flat = range <= 1e-12 * std::max({1.0, std::abs(lo), std::abs(hi)});
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (!std::isfinite(raw[i])) continue;
    if (flat) {
      out[i] = 1.0;
    } else {
      const double t = (raw[i] - lo) / range;
      out[i] = std::clamp(benefit ? t : 1.0 - t, 0.0, 1.0);
    }
  }
  return out;
}

}  // namespace nbs
}  // namespace picker_localisation
