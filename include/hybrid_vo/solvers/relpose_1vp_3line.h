#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// 0-3-1: one VP match and three coplanar segment matches (paper Sec. 2.2.3). Their three pairwise
// junctions become point matches for 3-0-1; cheirality is checked on the segments.
int relpose_1vp_3line(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                      const std::array<LineSegment, 3>& s1, const std::array<LineSegment, 3>& s2,
                      RelativePoses* poses, bool vp_sign_known = false);

}  // namespace hybrid_vo
