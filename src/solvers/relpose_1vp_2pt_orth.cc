#include "hybrid_vo/solvers/relpose_1vp_2pt_orth.h"

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/solvers/relpose_1vp_orthline_2pt.h"

namespace hybrid_vo {

int relpose_1vp_2pt_orth(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                         const std::array<Eigen::Vector2d, 2>& x1,
                         const std::array<Eigen::Vector2d, 2>& x2, RelativePoses* poses,
                         bool vp_sign_known) {
  MatchView witnesses;
  witnesses.x1 = x1.data();
  witnesses.x2 = x2.data();
  witnesses.num_points = 2;
  const Eigen::Vector3d l1 = homogeneous(x1[0]).cross(homogeneous(x1[1]));
  const Eigen::Vector3d l2 = homogeneous(x2[0]).cross(homogeneous(x2[1]));
  return relpose_1vp_orthline_2pt(v1, v2, l1, l2, x1.data(), x2.data(), witnesses, vp_sign_known,
                                  poses);
}

}  // namespace hybrid_vo
