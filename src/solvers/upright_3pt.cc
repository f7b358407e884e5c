#include "hybrid_vo/solvers/upright_3pt.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "hybrid_vo/solvers/polynomial.h"

namespace hybrid_vo {
namespace {

// a(y) = a0 + a1 y + a2 y^2 = ((1 + y^2) R_y q1) x q2.
struct QuadraticVector {
  Eigen::Vector3d c[3];
  Eigen::Vector3d at(double y) const { return c[0] + y * (c[1] + y * c[2]); }
};

QuadraticVector constraint(const Eigen::Vector3d& q1, const Eigen::Vector3d& q2) {
  QuadraticVector a;
  a.c[0] = q1.cross(q2);
  a.c[1] = Eigen::Vector3d(-2.0 * q1.z(), 0.0, 2.0 * q1.x()).cross(q2);
  a.c[2] = Eigen::Vector3d(-q1.x(), q1.y(), -q1.z()).cross(q2);
  return a;
}

// Null vector of the three constraint rows from their best-conditioned pair.
Eigen::Vector3d null_vector(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                            const Eigen::Vector3d& c) {
  Eigen::Vector3d best = a.cross(b);
  const Eigen::Vector3d ac = a.cross(c), bc = b.cross(c);
  if (ac.squaredNorm() > best.squaredNorm()) best = ac;
  if (bc.squaredNorm() > best.squaredNorm()) best = bc;
  return best;
}

}  // namespace

Eigen::Matrix3d rotation_about_y(double cos_phi, double sin_phi) {
  Eigen::Matrix3d R;
  R << cos_phi, 0.0, -sin_phi, 0.0, 1.0, 0.0, sin_phi, 0.0, cos_phi;
  return R;
}

int upright_relpose_3pt(const Eigen::Vector3d* q1, const Eigen::Vector3d* q2, Eigen::Matrix3d* R,
                        Eigen::Vector3d* t) {
  const QuadraticVector a[3] = {constraint(q1[0], q2[0]), constraint(q1[1], q2[1]),
                                constraint(q1[2], q2[2])};
  // det = a_0 . (a_1 x a_2), a sextic in y.
  Eigen::Vector3d cross[5];
  for (auto& v : cross) v.setZero();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) cross[i + j] += a[1].c[i].cross(a[2].c[j]);
  double sextic[7] = {0, 0, 0, 0, 0, 0, 0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 5; ++j) sextic[i + j] += a[0].c[i].dot(cross[j]);

  // Divide out (1 + y^2) = 0 (where R_y has rank one and every a_i is orthogonal to (1, 0, i)).
  // High and low coefficients are exact from either end; the middle one is averaged.
  double quartic[5];
  quartic[4] = sextic[6];
  quartic[3] = sextic[5];
  quartic[0] = sextic[0];
  quartic[1] = sextic[1];
  quartic[2] = 0.5 * ((sextic[4] - sextic[6]) + (sextic[2] - sextic[0]));

  double ys[4];
  const int num_roots = real_roots_quartic(quartic, ys);
  int count = 0;
  for (int r = 0; r < num_roots; ++r) {
    const double y = ys[r];
    const double w = 1.0 / (1.0 + y * y);
    Eigen::Vector3d tr = null_vector(a[0].at(y), a[1].at(y), a[2].at(y));
    const double norm = tr.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) continue;
    R[count] = rotation_about_y((1.0 - y * y) * w, 2.0 * y * w);
    t[count] = tr / norm;
    ++count;
  }
  // y = tan(phi / 2) cannot express phi = pi; it shows up as a vanishing leading coefficient.
  double scale = 0.0;
  for (double c : quartic) scale = std::max(scale, std::abs(c));
  if (std::abs(quartic[4]) <= 1e-12 * scale && count < 4) {
    // At y -> infinity, a(y) / y^2 -> a2.
    Eigen::Vector3d tr = null_vector(a[0].c[2], a[1].c[2], a[2].c[2]);
    const double norm = tr.norm();
    if (norm > 0.0 && std::isfinite(norm)) {
      R[count] = rotation_about_y(-1.0, 0.0);
      t[count] = tr / norm;
      ++count;
    }
  }
  return count;
}

}  // namespace hybrid_vo
