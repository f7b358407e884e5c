#include "hybrid_vo/geometry/epipolar_error.h"

#include <cmath>

#include <Eigen/Dense>

namespace hybrid_vo {

double sampson_error_px(const PinholeCamera& camera1, const PinholeCamera& camera2,
                        const RelativePose& pose, const Eigen::Vector2d& x1,
                        const Eigen::Vector2d& x2) {
  if (!(pose.t.norm() > 0.0) || !x1.allFinite() || !x2.allFinite()) return NAN;
  const Eigen::Matrix3d F =
      camera2.K().inverse().transpose() * pose.essential() * camera1.K().inverse();
  const Eigen::Vector3d a = x1.homogeneous(), b = x2.homogeneous();
  const Eigen::Vector3d Fa = F * a, Fb = F.transpose() * b;
  const double gradient = Fa.head<2>().squaredNorm() + Fb.head<2>().squaredNorm();
  if (!(gradient > 0.0)) return NAN;
  return std::abs(b.dot(Fa)) / std::sqrt(gradient);
}

}  // namespace hybrid_vo
