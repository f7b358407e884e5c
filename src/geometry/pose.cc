#include "hybrid_vo/geometry/pose.h"

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

Eigen::Matrix3d RelativePose::essential() const { return skew(t) * R; }

RelativePose relative_from_world_to_camera(const Eigen::Matrix3d& R1, const Eigen::Vector3d& t1,
                                           const Eigen::Matrix3d& R2, const Eigen::Vector3d& t2) {
  const Eigen::Matrix3d R = R2 * R1.transpose();
  return {R, t2 - R * t1};
}

}  // namespace hybrid_vo
