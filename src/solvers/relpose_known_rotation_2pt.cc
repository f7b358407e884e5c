#include "hybrid_vo/solvers/relpose_known_rotation_2pt.h"

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

int relpose_known_rotation_2pt(const Eigen::Matrix3d& R, const std::array<Eigen::Vector2d, 2>& x1,
                               const std::array<Eigen::Vector2d, 2>& x2, RelativePoses* poses) {
  poses->clear();
  if (!all_finite(R) || !all_finite(x1[0]) || !all_finite(x1[1]) || !all_finite(x2[0]) ||
      !all_finite(x2[1]))
    return 0;
  const Eigen::Vector3d n0 = (R * homogeneous(x1[0])).cross(homogeneous(x2[0]));
  const Eigen::Vector3d n1 = (R * homogeneous(x1[1])).cross(homogeneous(x2[1]));
  Eigen::Vector3d t = n0.cross(n1);
  const double norm = t.norm();
  // Zero when both matches lie on one epipolar plane (or a match has no parallax at all).
  if (!(norm > 1e-14 * n0.norm() * n1.norm()) || !std::isfinite(norm)) return 0;
  t /= norm;
  MatchView witnesses;
  witnesses.x1 = x1.data();
  witnesses.x2 = x2.data();
  witnesses.num_points = 2;
  if (!orient_translation(R, &t, witnesses)) return 0;
  poses->emplace_back(R, t);
  return 1;
}

}  // namespace hybrid_vo
