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

double pose_auc(std::vector<double> errors, double threshold) {
  if (errors.empty() || !(threshold > 0.0)) return 0.0;
  for (double& e : errors)
    if (!std::isfinite(e)) e = INFINITY;
  std::sort(errors.begin(), errors.end());
  const double n = static_cast<double>(errors.size());
  // Trapezoids through the points (e_k, k / n) from (0, 0), cut at the threshold: exactly
  // SuperGlue's np.trapz, which the published AUC numbers use.
  double area = 0.0, previous_error = 0.0, previous_recall = 0.0;
  for (size_t k = 0; k < errors.size() && errors[k] <= threshold; ++k) {
    const double recall = (k + 1) / n;
    area += (errors[k] - previous_error) * 0.5 * (previous_recall + recall);
    previous_error = errors[k];
    previous_recall = recall;
  }
  area += (threshold - previous_error) * previous_recall;
  return area / threshold;
}

}  // namespace hybrid_vo
