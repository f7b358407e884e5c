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

// Null vector of the three constraint rows from their best-conditioned pair, not normalised
// (cheirality needs only its direction); its squared norm, 0 when all three pairs are parallel.
double null_vector(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   Eigen::Vector3d* t) {
  Eigen::Vector3d best = cross(a, b);
  double best_norm2 = best.squaredNorm();
  const Eigen::Vector3d ac = cross(a, c), bc = cross(b, c);
  const double ac_norm2 = ac.squaredNorm(), bc_norm2 = bc.squaredNorm();
  if (ac_norm2 > best_norm2) best = ac, best_norm2 = ac_norm2;
  if (bc_norm2 > best_norm2) best = bc, best_norm2 = bc_norm2;
  if (!(best_norm2 > 0.0) || !std::isfinite(best_norm2)) return 0.0;
  *t = best;
  return best_norm2;
}

// What the cheirality votes of every candidate share: with r = R_y q1 (the ray of camera 1 in the
// upright frame of camera 2), |r|^2 = |q1|^2, q2 . r = c alpha + s beta + gamma, and
// r . t = q1 . (R_y^T t).
struct Matches {
  const Eigen::Vector3d* q1;
  const Eigen::Vector3d* q2;
  double rr[3], qq[3], alpha[3], beta[3], gamma[3];
};

Matches prepare(const Eigen::Vector3d* q1, const Eigen::Vector3d* q2) {
  Matches m;
  m.q1 = q1;
  m.q2 = q2;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d &a = q1[i], &b = q2[i];
    m.rr[i] = a.squaredNorm();
    m.qq[i] = b.squaredNorm();
    m.alpha[i] = b.x() * a.x() + b.z() * a.z();
    m.beta[i] = b.z() * a.x() - b.x() * a.z();
    m.gamma[i] = b.y() * a.y();
  }
  return m;
}

// Completes a candidate from its null vector t, |t|^2 = t_norm2: keeps it when some sign of t puts
// the three matches in front of both cameras (the votes of orient_translation_rays), or always
// when not orienting; then t to unit length.
inline bool finish(const Matches& m, bool orient, double t_norm2, UprightPose* pose) {
  Eigen::Vector3d& t = pose->t;
  if (orient) {
    const double c = pose->cos_phi, s = pose->sin_phi;
    // R_y^T t, for r . t.
    const double ux = c * t.x() + s * t.z(), uz = c * t.z() - s * t.x();
    int sign = 0;
    for (int i = 0; i < 3 && sign != kCheiralityConflict; ++i) {
      const Eigen::Vector3d &a = m.q1[i], &b = m.q2[i];
      const double qr = c * m.alpha[i] + s * m.beta[i] + m.gamma[i];
      const double qt = b.dot(t), rt = a.x() * ux + a.y() * t.y() + a.z() * uz;
      sign = combine_cheirality_votes(sign, cheirality_vote(m.rr[i], m.qq[i], qr, qt, rt, t_norm2));
    }
    if (sign == kCheiralityConflict) return false;
    if (sign < 0) t = -t;
  }
  t *= 1.0 / std::sqrt(t_norm2);
  return true;
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

  Matches m;
  if (orient_t) m = prepare(q1, q2);
  double ys[4];
  const int num_roots = real_roots_quartic(quartic, ys);
  int count = 0;
  for (int r = 0; r < num_roots; ++r) {
    const double y = ys[r];
    UprightPose& pose = poses[count];
    const double t_norm2 = null_vector(a[0].at(y), a[1].at(y), a[2].at(y), &pose.t);
    if (t_norm2 == 0.0) continue;
    const double w = 1.0 / (1.0 + y * y);
    pose.cos_phi = (1.0 - y * y) * w;
    pose.sin_phi = 2.0 * y * w;
    if (finish(m, orient_t, t_norm2, &pose)) ++count;
  }
  // y = tan(phi / 2) cannot express phi = pi; it shows up as a vanishing leading coefficient.
  double scale = 0.0;
  for (double v : quartic) scale = std::max(scale, std::abs(v));
  if (std::abs(quartic[4]) <= 1e-12 * scale && count < 4) {
    // At y -> infinity, a(y) / y^2 -> a2.
    UprightPose& pose = poses[count];
    const double t_norm2 = null_vector(a[0].c[2], a[1].c[2], a[2].c[2], &pose.t);
    if (t_norm2 > 0.0) {
      pose.cos_phi = -1.0;
      pose.sin_phi = 0.0;
      if (finish(m, orient_t, t_norm2, &pose)) ++count;
    }
  }
  return count;
}

}  // namespace hybrid_vo
