#include "hybrid_vo/solvers/upright_3pt.h"

#include <algorithm>
#include <cmath>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/solvers/polynomial.h"

namespace hybrid_vo {
namespace {

inline Eigen::Vector3d cross(const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  return {u.y() * v.z() - u.z() * v.y(), u.z() * v.x() - u.x() * v.z(),
          u.x() * v.y() - u.y() * v.x()};
}

// a(y) = c[0] + y c[1] + y^2 c[2] = ((1 + y^2) R_y q1) x q2, where
// (1 + y^2) R_y q1 = q1 + y (-2 q1_z, 0, 2 q1_x) + y^2 (-q1_x, q1_y, -q1_z); the three cross
// products written out.
struct QuadraticVector {
  Eigen::Vector3d c[3];
  Eigen::Vector3d at(double y) const { return c[0] + y * (c[1] + y * c[2]); }
};

QuadraticVector constraint(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  QuadraticVector q;
  q.c[0] = cross(a, b);
  q.c[1] = {-2.0 * a.x() * b.y(), 2.0 * (a.x() * b.x() + a.z() * b.z()), -2.0 * a.z() * b.y()};
  q.c[2] = {a.y() * b.z() + a.z() * b.y(), a.x() * b.z() - a.z() * b.x(),
            -a.x() * b.y() - a.y() * b.x()};
  return q;
}

// Null vector of the three constraint rows from their best-conditioned pair, unit length; false
// when all three pairs are parallel.
bool unit_null_vector(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      Eigen::Vector3d* t) {
  Eigen::Vector3d best = cross(a, b);
  double best_norm2 = best.squaredNorm();
  const Eigen::Vector3d ac = cross(a, c), bc = cross(b, c);
  const double ac_norm2 = ac.squaredNorm(), bc_norm2 = bc.squaredNorm();
  if (ac_norm2 > best_norm2) best = ac, best_norm2 = ac_norm2;
  if (bc_norm2 > best_norm2) best = bc, best_norm2 = bc_norm2;
  if (!(best_norm2 > 0.0) || !std::isfinite(best_norm2)) return false;
  *t = best / std::sqrt(best_norm2);
  return true;
}

// Keeps the candidate when some sign of t puts the three matches in front of both cameras,
// decided on the rays R_y q1 and q2 of the upright frame.
bool orient(const Eigen::Vector3d* q1, const Eigen::Vector3d* q2, UprightPose* pose) {
  const double c = pose->cos_phi, s = pose->sin_phi;
  Eigen::Vector3d r[3];
  for (int i = 0; i < 3; ++i)
    r[i] = {c * q1[i].x() - s * q1[i].z(), q1[i].y(), s * q1[i].x() + c * q1[i].z()};
  return orient_translation_rays(r, q2, 3, &pose->t);
}

}  // namespace

Eigen::Matrix3d rotation_about_y(double cos_phi, double sin_phi) {
  Eigen::Matrix3d R;
  R << cos_phi, 0.0, -sin_phi, 0.0, 1.0, 0.0, sin_phi, 0.0, cos_phi;
  return R;
}

int upright_relpose_3pt(const Eigen::Vector3d* q1, const Eigen::Vector3d* q2, bool orient_t,
                        UprightPose* poses) {
  const QuadraticVector a[3] = {constraint(q1[0], q2[0]), constraint(q1[1], q2[1]),
                                constraint(q1[2], q2[2])};
  // det = a_0 . (a_1 x a_2), a sextic in y; its y^3 coefficient is not needed below.
  Eigen::Vector3d x[5];
  x[0] = cross(a[1].c[0], a[2].c[0]);
  x[1] = cross(a[1].c[0], a[2].c[1]) + cross(a[1].c[1], a[2].c[0]);
  x[2] = cross(a[1].c[0], a[2].c[2]) + cross(a[1].c[1], a[2].c[1]) + cross(a[1].c[2], a[2].c[0]);
  x[3] = cross(a[1].c[1], a[2].c[2]) + cross(a[1].c[2], a[2].c[1]);
  x[4] = cross(a[1].c[2], a[2].c[2]);
  const Eigen::Vector3d* c = a[0].c;
  const double s0 = c[0].dot(x[0]);
  const double s1 = c[0].dot(x[1]) + c[1].dot(x[0]);
  const double s2 = c[0].dot(x[2]) + c[1].dot(x[1]) + c[2].dot(x[0]);
  const double s4 = c[0].dot(x[4]) + c[1].dot(x[3]) + c[2].dot(x[2]);
  const double s5 = c[1].dot(x[4]) + c[2].dot(x[3]);
  const double s6 = c[2].dot(x[4]);

  // Divide out (1 + y^2) = 0 (where R_y has rank one and every a_i is orthogonal to (1, 0, i)).
  // High and low coefficients are exact from either end; the middle one is averaged.
  const double quartic[5] = {s0, s1, 0.5 * ((s4 - s6) + (s2 - s0)), s5, s6};

  double ys[4];
  const int num_roots = real_roots_quartic(quartic, ys);
  int count = 0;
  for (int r = 0; r < num_roots; ++r) {
    const double y = ys[r];
    UprightPose& pose = poses[count];
    if (!unit_null_vector(a[0].at(y), a[1].at(y), a[2].at(y), &pose.t)) continue;
    const double w = 1.0 / (1.0 + y * y);
    pose.cos_phi = (1.0 - y * y) * w;
    pose.sin_phi = 2.0 * y * w;
    if (orient_t && !orient(q1, q2, &pose)) continue;
    ++count;
  }
  // y = tan(phi / 2) cannot express phi = pi; it shows up as a vanishing leading coefficient.
  double scale = 0.0;
  for (double v : quartic) scale = std::max(scale, std::abs(v));
  if (std::abs(quartic[4]) <= 1e-12 * scale && count < 4) {
    // At y -> infinity, a(y) / y^2 -> a2.
    UprightPose& pose = poses[count];
    if (unit_null_vector(a[0].c[2], a[1].c[2], a[2].c[2], &pose.t)) {
      pose.cos_phi = -1.0;
      pose.sin_phi = 0.0;
      if (!orient_t || orient(q1, q2, &pose)) ++count;
    }
  }
  return count;
}

}  // namespace hybrid_vo
