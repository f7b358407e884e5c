#pragma once

// Internal: LBD as line_description.cc computes it and line_matching.cc compares it.

#include <cmath>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// A descriptor row (LineFeatures::descriptors) holds, per octave, one of these.
constexpr int kLbdBytes = 32;   // 256-bit binary LBD
constexpr int kLbdFloats = 72;  // float LBD: 9 bands x 8 statistics

// The direction of p1 -> p2 (radians): LBD describes a segment along it, and matched segments'
// rotation is measured by it.
inline double direction_angle(const LineSegment& s) {
  return std::atan2(s.p2.y() - s.p1.y(), s.p2.x() - s.p1.x());
}

}  // namespace hybrid_vo
