#pragma once

// Internal: the geometric filter of line matching (LineMatchingOptions::geometric_filter).

#include <cmath>
#include <vector>

#include "hybrid_vo/features/line_matching.h"

namespace hybrid_vo {

// An angle in (-pi, pi].
inline double wrap_angle(double a) {
  while (a > M_PI) a -= 2 * M_PI;
  while (a <= -M_PI) a += 2 * M_PI;
  return a;
}

// A tentative match of segment i (image 1) with segment j (image 2).
struct Tentative {
  int i = 0, j = 0;
  bool anchor = false;    // mutual nearest neighbours that passed the ratio test
  double rotation = 0.0;  // from the image-1 to the image-2 direction, radians (wrap_angle)
};

// Which of the tentative matches between segments `a` (image 1) and `b` (image 2) agree with the
// images' geometric change: the global rotation, the local consensus and the position check of
// LineMatchingOptions.
std::vector<bool> geometric_filter(const std::vector<LineSegment>& a,
                                   const std::vector<LineSegment>& b,
                                   const std::vector<Tentative>& tentative,
                                   const LineMatchingOptions& options);

}  // namespace hybrid_vo
