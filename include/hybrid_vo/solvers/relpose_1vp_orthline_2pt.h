#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// 2-1-1-perp: one VP match, one segment match whose 3D direction is orthogonal to the VP's, and
// two point matches (Elqursh and Elgammal 2011). The line's direction l x v is a second VP
// (paper supp. Sec. A.3), which reduces the problem to 2-0-2. The sign of that derived VP is never
// known. Returns the number of poses.
int relpose_1vp_orthline_2pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                             const LineSegment& s1, const LineSegment& s2,
                             const std::array<Eigen::Vector2d, 2>& x1,
                             const std::array<Eigen::Vector2d, 2>& x2, RelativePoses* poses,
                             bool vp_sign_known = false);

// Same with the orthogonal line given as homogeneous lines and cheirality on `witnesses`.
int relpose_1vp_orthline_2pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                             const Eigen::Vector3d& l1, const Eigen::Vector3d& l2,
                             const Eigen::Vector2d* x1, const Eigen::Vector2d* x2,
                             const MatchView& witnesses, bool vp_sign_known, RelativePoses* poses);

}  // namespace hybrid_vo
