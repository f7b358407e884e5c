#include "hybrid_vo/geometry/homogeneous.h"

#include <Eigen/Geometry>

namespace hybrid_vo {

Eigen::Vector3d LineSegment::line() const { return homogeneous(p1).cross(homogeneous(p2)); }

Eigen::Vector3d line_through(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector3d l = homogeneous(a).cross(homogeneous(b));
  const double n = l.head<2>().norm();
  if (!(n > 0.0)) return Eigen::Vector3d::Zero();
  return l / n;
}

bool intersect_lines(const Eigen::Vector3d& l1, const Eigen::Vector3d& l2, Eigen::Vector2d* x,
                     double max_norm) {
  const Eigen::Vector3d p = l1.cross(l2);
  if (!(std::abs(p.z()) * max_norm > p.head<2>().norm())) return false;
  *x = p.head<2>() / p.z();
  return true;
}

}  // namespace hybrid_vo
