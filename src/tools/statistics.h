#pragma once

// Small statistics shared by the benchmarks and evaluations (header-only: the tools link
// different libraries).

#include <algorithm>
#include <cmath>
#include <vector>

namespace hybrid_vo {
namespace tools {

// The upper median (the middle element; of two middles the higher); NaN when empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace tools
}  // namespace hybrid_vo
