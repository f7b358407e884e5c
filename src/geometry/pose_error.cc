#include "hybrid_vo/geometry/pose_error.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace hybrid_vo {

double rotation_error(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  const Eigen::Matrix3d M = R_a.transpose() * R_b;
  const Eigen::Vector3d twice_sin_axis(M(2, 1) - M(1, 2), M(0, 2) - M(2, 0), M(1, 0) - M(0, 1));
  return std::atan2(0.5 * twice_sin_axis.norm(), 0.5 * (M.trace() - 1.0));
}

double translation_error(const Eigen::Vector3d& t_a, const Eigen::Vector3d& t_b) {
  const double na = t_a.norm(), nb = t_b.norm();
  if (na == 0.0 && nb == 0.0) return 0.0;
  if (na == 0.0 || nb == 0.0) return 0.5 * M_PI;
  return std::atan2(t_a.cross(t_b).norm(), t_a.dot(t_b));
}

double pose_error(const RelativePose& estimate, const RelativePose& truth) {
  return std::max(rotation_error(estimate.R, truth.R), translation_error(estimate.t, truth.t));
}

}  // namespace hybrid_vo
