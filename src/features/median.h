#pragma once

// Internal: the median the front end's robust fits share (point_flow_field.cc, vignetting.cc).

#include <algorithm>
#include <vector>

namespace hybrid_vo {

// The upper median (of two middles the higher); `v` must not be empty.
inline double median_of(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace hybrid_vo
