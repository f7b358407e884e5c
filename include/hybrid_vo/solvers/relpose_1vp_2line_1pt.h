#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// 1-2-1-perp: one VP match, two intersecting segment matches of which the first is orthogonal to
// the VP's direction, and one point match (paper Sec. 2.2.4). The segments' junction is the
// second point of 2-1-1-perp. Returns the number of poses.
int relpose_1vp_2line_1pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                          const std::array<LineSegment, 2>& s1,
                          const std::array<LineSegment, 2>& s2, const Eigen::Vector2d& x1,
                          const Eigen::Vector2d& x2, RelativePoses* poses,
                          bool vp_sign_known = false);

}  // namespace hybrid_vo
