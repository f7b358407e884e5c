#include "hybrid_vo/solvers/relpose_1vp_orthline_2pt.h"

#include <Eigen/Geometry>

#include "hybrid_vo/solvers/relpose_2vp_2pt.h"

namespace hybrid_vo {

int relpose_1vp_orthline_2pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                             const Eigen::Vector3d& l1, const Eigen::Vector3d& l2,
                             const Eigen::Vector2d* x1, const Eigen::Vector2d* x2,
                             const MatchView& witnesses, bool vp_sign_known, RelativePoses* poses) {
  poses->clear();
  // The 3D line lies in the plane back-projected from l and is orthogonal to the VP direction.
  const std::array<Eigen::Vector3d, 2> vps1 = {v1, l1.cross(v1)};
  const std::array<Eigen::Vector3d, 2> vps2 = {v2, l2.cross(v2)};
  const double n1 = vps1[1].norm(), n2 = vps2[1].norm();
  // The line's plane is orthogonal to the VP (the line is the VP's horizon): no second direction.
  if (!(n1 > 1e-12 * l1.norm() * v1.norm() && n2 > 1e-12 * l2.norm() * v2.norm())) return 0;
  return relpose_2vp_2pt(vps1, vps2, x1, x2, witnesses, VpSigns{vp_sign_known, false}, poses);
}

int relpose_1vp_orthline_2pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                             const LineSegment& s1, const LineSegment& s2,
                             const std::array<Eigen::Vector2d, 2>& x1,
                             const std::array<Eigen::Vector2d, 2>& x2, RelativePoses* poses,
                             bool vp_sign_known) {
  MatchView witnesses;
  witnesses.x1 = x1.data();
  witnesses.x2 = x2.data();
  witnesses.num_points = 2;
  witnesses.s1 = &s1;
  witnesses.s2 = &s2;
  witnesses.num_segments = 1;
  return relpose_1vp_orthline_2pt(v1, v2, s1.line(), s2.line(), x1.data(), x2.data(), witnesses,
                                  vp_sign_known, poses);
}

}  // namespace hybrid_vo
