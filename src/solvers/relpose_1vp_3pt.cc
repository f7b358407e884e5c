#include "hybrid_vo/solvers/relpose_1vp_3pt.h"

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/solvers/upright_3pt.h"

namespace hybrid_vo {
namespace {

// A rotation taking the unit vector a onto the y-axis: Rodrigues' formula with the axis
// a x e_y = (-a_z, 0, a_x) and cos = a_y written out, R = a_y I + [k]x + k k^T / (1 + a_y), a
// dozen flops where rotation_between forms [k]x^2 by a matrix product. For a_y < -0.5 (as
// rotation_between), R takes a onto -e_y and a half-turn about z follows, which keeps 1 + a_y
// away from 0.
Eigen::Matrix3d rotation_onto_y_axis(const Eigen::Vector3d& a) {
  const bool flip = a.y() < -0.5;
  const double c = flip ? -a.y() : a.y();
  // Onto -e_y: the same formula for (-a_x, -a_y, a_z) (a half-turn about z), then undone.
  const double x = flip ? -a.x() : a.x(), z = a.z();
  const double k = 1.0 / (1.0 + c);
  Eigen::Matrix3d R;
  R << c + z * z * k, -x, -x * z * k,
       x, c, z,
       -x * z * k, -z, c + x * x * k;
  if (flip) R.leftCols<2>() = -R.leftCols<2>();  // R diag(-1, -1, 1)
  return R;
}

}  // namespace

int relpose_1vp_3pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2, const Eigen::Vector2d* x1,
                    const Eigen::Vector2d* x2, const MatchView& witnesses, bool vp_sign_known,
                    RelativePoses* poses) {
  poses->clear();
  const double n1 = v1.norm(), n2 = v2.norm();
  if (!(n1 > 0.0 && n2 > 0.0) || !all_finite(v1) || !all_finite(v2)) return 0;
  // R = R2x^T R_y(phi) R1x, where R1x and R2x take the VPs to the y-axis (paper eq. 7).
  const Eigen::Matrix3d R1x = rotation_onto_y_axis(v1 / n1);
  const bool witnesses_are_sample = witnesses.num_segments == 0 && witnesses.num_points == 3 &&
                                    witnesses.x1 == x1 && witnesses.x2 == x2;
  Eigen::Vector3d q1[3], q2[3];
  for (int i = 0; i < 3; ++i) q1[i] = R1x * homogeneous(x1[i]);
  for (const double sign : {1.0, -1.0}) {
    if (sign < 0.0 && vp_sign_known) break;
    const Eigen::Matrix3d R2x = rotation_onto_y_axis(sign * v2 / n2);
    for (int i = 0; i < 3; ++i) q2[i] = R2x * homogeneous(x2[i]);
    // Cheirality in the upright frame, a rotation of camera 2's, when the three points are the
    // witnesses: no R for rejected roots.
    UprightPose upright[4];
    const int n = upright_relpose_3pt(q1, q2, witnesses_are_sample, upright);
    for (int k = 0; k < n; ++k) {
      const double c = upright[k].cos_phi, s = upright[k].sin_phi;
      Eigen::Vector3d t = upright[k].t;
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
