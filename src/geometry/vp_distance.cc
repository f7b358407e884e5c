#include "hybrid_vo/geometry/vp_distance.h"

#include <cmath>

namespace hybrid_vo {

bool tardif_distance(const Eigen::Vector3d& l, const Eigen::Vector2d& m, const Eigen::Vector3d& v,
                     double* r, Eigen::Vector3d* dr_dv) {
  const Eigen::Vector2d g = v.head<2>() - v.z() * m;
  const double g_norm = g.norm();
  if (!(g_norm > 1e-12 * v.norm())) return false;
  const double n = 0.5 * v.dot(l);
  *r = n / g_norm;
  if (dr_dv) {
    // dr/dv = l / 2 / |g| - n A^T g / |g|^3, with g = A v and A = [I2, -m].
    const Eigen::Vector3d A_t_g(g.x(), g.y(), -m.dot(g));
    *dr_dv = 0.5 * l / g_norm - n / (g_norm * g_norm * g_norm) * A_t_g;
  }
  return true;
}

double tardif_distance(const LineSegment& s, const Eigen::Vector3d& v) {
  double r;
  if (!tardif_distance(s.line(), s.midpoint(), v, &r) || !std::isfinite(r)) return INFINITY;
  return std::abs(r);
}

}  // namespace hybrid_vo
