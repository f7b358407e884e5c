#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// 3-0-1: relative pose from one vanishing point match and three point matches (paper Sec. 2.2.2).
// v1, v2 are VP directions (K^-1 v, any scale) with v2 ~ +-R v1. Both VPs are rotated onto the
// y-axis, which leaves the upright three-point problem (a quartic). Unless `vp_sign_known`
// (v2 = +R v1), the sign v2 = -R v1 is tried too. Returns the number of poses.
int relpose_1vp_3pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                    const std::array<Eigen::Vector2d, 3>& x1,
                    const std::array<Eigen::Vector2d, 3>& x2, RelativePoses* poses,
                    bool vp_sign_known = false);

// Same, deciding cheirality on `witnesses` instead of the three points (0-3-1 uses junctions,
// whose sign is unknown, and checks its segments instead).
int relpose_1vp_3pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2, const Eigen::Vector2d* x1,
                    const Eigen::Vector2d* x2, const MatchView& witnesses, bool vp_sign_known,
                    RelativePoses* poses);

}  // namespace hybrid_vo
