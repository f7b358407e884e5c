#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// 2-0-1-perp: one VP match and two point matches whose joining 3D line is orthogonal to the VP's
// direction (paper Sec. 2.2.5). The line through the points is the orthogonal line of
// 2-1-1-perp. Returns the number of poses.
int relpose_1vp_2pt_orth(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                         const std::array<Eigen::Vector2d, 2>& x1,
                         const std::array<Eigen::Vector2d, 2>& x2, RelativePoses* poses,
                         bool vp_sign_known = false);

}  // namespace hybrid_vo
