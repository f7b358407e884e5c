#include "hybrid_vo/solvers/relpose_2vp_2pt.h"

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

int relpose_2vp_2pt(const std::array<Eigen::Vector3d, 2>& v1,
                    const std::array<Eigen::Vector3d, 2>& v2, const Eigen::Vector2d* x1,
                    const Eigen::Vector2d* x2, const MatchView& witnesses, VpSigns signs,
                    RelativePoses* poses) {
  poses->clear();
  Eigen::Vector3d a[2], b[2];
  for (int i = 0; i < 2; ++i) {
    const double n1 = v1[i].norm(), n2 = v2[i].norm();
    if (!(n1 > 0.0 && n2 > 0.0) || !all_finite(v1[i]) || !all_finite(v2[i])) return 0;
    a[i] = v1[i] / n1;
    b[i] = v2[i] / n2;
  }
  // R maps the frame of (a0 + a1, a0 - a1) onto that of (s0 b0 + s1 b1, s0 b0 - s1 b1), the
  // least-squares alignment of both pairs (see rotation_from_two_directions). Flipping signs only
  // permutes and negates the two b-frame axes, so both frames are built once.
  const Eigen::Vector3d sa = a[0] + a[1], da = a[0] - a[1], sb = b[0] + b[1], db = b[0] - b[1];
  const double nsa = sa.norm(), nda = da.norm(), nsb = sb.norm(), ndb = db.norm();
  constexpr double kMin = 1e-9;
  if (!(nsa > kMin && nda > kMin && nsb > kMin && ndb > kMin)) return 0;  // parallel VPs
  Eigen::Matrix3d Fa;
  Fa.col(0) = sa / nsa;
  Fa.col(1) = da / nda;
  Fa.col(2) = Fa.col(0).cross(Fa.col(1));
  const Eigen::Vector3d u = sb / nsb, w = db / ndb, uw = u.cross(w);
  const Eigen::Vector3d p[2] = {homogeneous(x1[0]), homogeneous(x1[1])};
  const Eigen::Vector3d q[2] = {homogeneous(x2[0]), homogeneous(x2[1])};
  const double min_t = 1e-14 * p[0].norm() * q[0].norm() * p[1].norm() * q[1].norm();
  for (const double s0 : {1.0, -1.0}) {
    if (s0 < 0.0 && signs.first_known) break;
    for (const double s1 : {1.0, -1.0}) {
      if (s1 < 0.0 && signs.second_known) break;
      Eigen::Matrix3d Fb;
      if (s0 == s1) {
        Fb << s0 * u, s0 * w, uw;
      } else {
        Fb << s0 * w, s0 * u, -uw;
      }
      const Eigen::Matrix3d R = Fb * Fa.transpose();
      Eigen::Vector3d t = (R * p[0]).cross(q[0]).cross((R * p[1]).cross(q[1]));
      const double norm = t.norm();
      // Zero when the two epipolar planes coincide (both points on one epipolar plane).
      if (!(norm > min_t)) continue;
      t /= norm;
      if (!orient_translation(R, &t, witnesses)) continue;
      poses->emplace_back(R, t);
    }
  }
  return static_cast<int>(poses->size());
}

int relpose_2vp_2pt(const std::array<Eigen::Vector3d, 2>& v1,
                    const std::array<Eigen::Vector3d, 2>& v2,
                    const std::array<Eigen::Vector2d, 2>& x1,
                    const std::array<Eigen::Vector2d, 2>& x2, RelativePoses* poses,
                    bool vp_signs_known) {
  MatchView witnesses;
  witnesses.x1 = x1.data();
  witnesses.x2 = x2.data();
  witnesses.num_points = 2;
  return relpose_2vp_2pt(v1, v2, x1.data(), x2.data(), witnesses,
                         VpSigns{vp_signs_known, vp_signs_known}, poses);
}

}  // namespace hybrid_vo
