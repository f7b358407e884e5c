#pragma once

#include <vector>

#include <Eigen/Core>

namespace hybrid_vo {

// Relative pose between two cameras: X2 = R * X1 + t (DESIGN.md, "Conventions"; paper Sec. 2.1).
// Two-view solvers return a unit t; t = 0 means the motion is a pure rotation.
struct RelativePose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();

  RelativePose() = default;
  RelativePose(const Eigen::Matrix3d& R_, const Eigen::Vector3d& t_) : R(R_), t(t_) {}

  // E = [t]x R, so that x2^T E x1 = 0 for a point match.
  Eigen::Matrix3d essential() const;
  RelativePose inverse() const { return {R.transpose(), -R.transpose() * t}; }
  Eigen::Vector3d apply(const Eigen::Vector3d& X1) const { return R * X1 + t; }
  // Camera 2's centre in camera 1's frame.
  Eigen::Vector3d centre2() const { return -R.transpose() * t; }
};

using RelativePoses = std::vector<RelativePose>;

// Relative pose from two world-to-camera poses: R = R2 R1^T, t = t2 - R t1.
RelativePose relative_from_world_to_camera(const Eigen::Matrix3d& R1, const Eigen::Vector3d& t1,
                                           const Eigen::Matrix3d& R2, const Eigen::Vector3d& t2);

}  // namespace hybrid_vo
