#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// Which VP signs are known (v2 = +R v1) rather than ambiguous (v2 = +-R v1).
struct VpSigns {
  bool first_known = false;
  bool second_known = false;
};

// 2-0-2: relative pose from two VP matches and two point matches (paper Sec. 2.2; Salaün et al.
// 2016). The rotation aligns both VP pairs in closed form, for every ambiguous sign; then t is
// orthogonal to both epipolar plane normals R x1 x x2. Returns the number of poses (<= 4).
int relpose_2vp_2pt(const std::array<Eigen::Vector3d, 2>& v1,
                    const std::array<Eigen::Vector3d, 2>& v2,
                    const std::array<Eigen::Vector2d, 2>& x1,
                    const std::array<Eigen::Vector2d, 2>& x2, RelativePoses* poses,
                    bool vp_signs_known = false);

// Same with per-VP sign knowledge and cheirality decided on `witnesses`.
int relpose_2vp_2pt(const std::array<Eigen::Vector3d, 2>& v1,
                    const std::array<Eigen::Vector3d, 2>& v2, const Eigen::Vector2d* x1,
                    const Eigen::Vector2d* x2, const MatchView& witnesses, VpSigns signs,
                    RelativePoses* poses);

}  // namespace hybrid_vo
