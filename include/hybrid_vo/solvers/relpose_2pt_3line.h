#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// 2-3-0: two point matches and three coplanar segment matches (paper Sec. 2.2.1). The three
// pairwise junctions complete five point matches for 5-0-0; cheirality is checked on the two
// points and the segments.
int relpose_2pt_3line(const std::array<Eigen::Vector2d, 2>& x1,
                      const std::array<Eigen::Vector2d, 2>& x2,
                      const std::array<LineSegment, 3>& s1, const std::array<LineSegment, 3>& s2,
                      RelativePoses* poses);

}  // namespace hybrid_vo
