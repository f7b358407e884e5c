#include "hybrid_vo/solvers/relpose_1vp_3pt.h"

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/solvers/upright_3pt.h"

namespace hybrid_vo {

int relpose_1vp_3pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2, const Eigen::Vector2d* x1,
                    const Eigen::Vector2d* x2, const MatchView& witnesses, bool vp_sign_known,
                    RelativePoses* poses) {
  poses->clear();
  const double n1 = v1.norm(), n2 = v2.norm();
  if (!(n1 > 0.0 && n2 > 0.0) || !all_finite(v1) || !all_finite(v2)) return 0;
  // rotation_between rather than a closed-form Rodrigues matrix: the latter lost 2 more of 100k
  // random instances (bench_solvers 3-0-1) for ~290 fewer instructions per call.
  const Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();
  // R = R2x^T R_y(phi) R1x, where R1x and R2x take the VPs to the y-axis (paper eq. 7).
  const Eigen::Matrix3d R1x = rotation_between(v1 / n1, y_axis);
  const bool witnesses_are_sample = witnesses.num_segments == 0 && witnesses.num_points == 3 &&
                                    witnesses.x1 == x1 && witnesses.x2 == x2;
  Eigen::Vector3d q1[3], q2[3];
  for (int i = 0; i < 3; ++i) q1[i] = R1x * homogeneous(x1[i]);
  for (const double sign : {1.0, -1.0}) {
    if (sign < 0.0 && vp_sign_known) break;
    const Eigen::Matrix3d R2x = rotation_between(sign * v2 / n2, y_axis);
    for (int i = 0; i < 3; ++i) q2[i] = R2x * homogeneous(x2[i]);
    Eigen::Matrix3d Ry[4];
    Eigen::Vector3d ty[4];
    const int n = upright_relpose_3pt(q1, q2, Ry, ty);
    for (int k = 0; k < n; ++k) {
      const double c = Ry[k](0, 0), s = Ry[k](2, 0);
      Eigen::Vector3d t = ty[k];
      if (witnesses_are_sample) {
        // Cheirality in the upright frame, a rotation of camera 2's: no R for rejected roots.
        Eigen::Vector3d r[3];
        for (int i = 0; i < 3; ++i)
          r[i] << c * q1[i].x() - s * q1[i].z(), q1[i].y(), s * q1[i].x() + c * q1[i].z();
        if (!orient_translation_rays(r, q2, 3, &t)) continue;
      }
      // Ry R1x from the rows of R1x (Ry = rotation_about_y(c, s)), then R2x^T.
      Eigen::Matrix3d RyR1;
      RyR1.row(0) = c * R1x.row(0) - s * R1x.row(2);
      RyR1.row(1) = R1x.row(1);
      RyR1.row(2) = s * R1x.row(0) + c * R1x.row(2);
      const Eigen::Matrix3d R = R2x.transpose() * RyR1;
      t = R2x.transpose() * t;
      if (!witnesses_are_sample && !orient_translation(R, &t, witnesses)) continue;
      poses->emplace_back(R, t);
    }
  }
  return static_cast<int>(poses->size());
}

int relpose_1vp_3pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                    const std::array<Eigen::Vector2d, 3>& x1,
                    const std::array<Eigen::Vector2d, 3>& x2, RelativePoses* poses,
                    bool vp_sign_known) {
  MatchView witnesses;
  witnesses.x1 = x1.data();
  witnesses.x2 = x2.data();
  witnesses.num_points = 3;
  return relpose_1vp_3pt(v1, v2, x1.data(), x2.data(), witnesses, vp_sign_known, poses);
}

}  // namespace hybrid_vo
