#pragma once

// Small statistics shared by the benchmarks and evaluations (header-only: the tools link
// different libraries).

#include <algorithm>
#include <cmath>
#include <vector>

namespace hybrid_vo {
namespace evaluation {

// The upper median (the middle element; of two middles the higher); NaN when empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The p-quantile (0..1) by the nearest rank; NaN when empty.
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

}  // namespace evaluation
}  // namespace hybrid_vo
