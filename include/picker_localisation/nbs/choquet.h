// Fuzzy measures and the discrete Choquet integral of Navigate-and-Seek Sec. V, Eq. 13. ROS-free.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace picker_localisation {
namespace nbs {

constexpr std::size_t kMaxCriteria = 16;  // subsets are bit masks over the criteria

// Interaction of a pair of criteria: bonus > 0 synergy (both good together is worth more than the sum),
// bonus < 0 redundancy (they measure much the same thing).
struct CriterionInteraction {
  std::size_t a = 0;
  std::size_t b = 0;
  double bonus = 0.0;
};

// A fuzzy measure (capacity) mu over the subsets of n criteria: mu(empty) = 0, mu(all) = 1, and monotone
// (A subset of B => mu(A) <= mu(B)). Subset A is the bit mask with bit i set when criterion i is in A.
class FuzzyMeasure {
 public:
  // Checked construction from explicit values, one per subset (2^n entries, index = bit mask). Throws
  // std::invalid_argument when the values are not a fuzzy measure (tolerance 1e-9).
  static FuzzyMeasure fromSubsetValues(std::vector<double> values);

  // The measure built from the Table I weights and pair interactions. How a subset A is valued:
  //   1. the weights are scaled to sum to 1 (Table I's already do: 0.3 + 0.1 + 0.35 + 0.25);
  //   2. v(A) = clamp(sum_{i in A} w_i + sum_{pairs {a,b} in A} bonus_ab, 0, 1);
  //   3. monotone closure: mu(A) = max over B subset of A of v(B) (so a redundancy can never make a larger
  //      set worth less than a smaller one);
  //   4. mu(all) = 1, mu(empty) = 0.
  // Without interactions this is the additive measure and the integral is the weighted sum. Throws
  // std::invalid_argument on a negative or non-finite weight, weights summing to 0, more than kMaxCriteria
  // criteria, or an interaction naming an unknown criterion or a criterion with itself.
  static FuzzyMeasure fromWeights(const std::vector<double>& weights,
                                  const std::vector<CriterionInteraction>& interactions = {});

  std::size_t numCriteria() const { return n_; }
  double operator()(std::uint32_t subset) const { return mu_.at(subset); }
  const std::vector<double>& values() const { return mu_; }
  // Empty when mu is a fuzzy measure, else the first violation found.
  static std::string checkMeasure(const std::vector<double>& values);

 private:
  FuzzyMeasure(std::size_t n, std::vector<double> mu) : n_(n), mu_(std::move(mu)) {}
  std::size_t n_ = 0;
  std::vector<double> mu_;
};

// Discrete Choquet integral (Eq. 13): with the utilities sorted u_(1) <= ... <= u_(n) and u_(0) = 0,
//   f = sum_j (u_(j) - u_(j-1)) * mu(A_(j)),  A_(j) = {(j), ..., (n)} (the criteria whose utility is at least
// u_(j)). Ties are broken by criterion index; the result does not depend on it (tied terms add zero).
// Utilities are expected in [0, 1]; throws std::invalid_argument when their count differs from the measure's.
double choquetIntegral(const std::vector<double>& utilities, const FuzzyMeasure& mu);

// Min-max normalisation of one criterion over the candidates (Sec. V): benefit criteria map the largest raw
// value to 1, cost criteria map the smallest to 1. A criterion that does not discriminate (range below
// 1e-12 of the largest magnitude, or all equal) gives every candidate 1, i.e. every candidate fully satisfies
// it and the other criteria decide. Non-finite raw values get 0 (the worst).
std::vector<double> minMaxNormalise(const std::vector<double>& raw, bool benefit);

}  // namespace nbs
}  // namespace picker_localisation
