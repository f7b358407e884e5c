#pragma once

#include <Eigen/Core>

#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// Angle of R_a^T R_b in radians, accurate down to ~1e-16 (atan2 form, not acos).
double rotation_error(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

// Angle between two translation directions in radians; pi/2 when exactly one is zero.
double translation_error(const Eigen::Vector3d& t_a, const Eigen::Vector3d& t_b);

// max(rotation error, translation error): the pose error behind AUC@5/10/20 (DESIGN.md).
double pose_error(const RelativePose& estimate, const RelativePose& truth);

}  // namespace hybrid_vo
