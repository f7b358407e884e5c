#pragma once

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// Junction of two segment matches as a point match: the intersections of the infinite lines in
// both images (paper supp. Sec. B: the junction carries exactly the coplanarity constraint).
// False when the lines are parallel in either image, where the junction says nothing.
bool junction_match(const LineSegment& a1, const LineSegment& b1, const LineSegment& a2,
                    const LineSegment& b2, Eigen::Vector2d* x1, Eigen::Vector2d* x2);

}  // namespace hybrid_vo
