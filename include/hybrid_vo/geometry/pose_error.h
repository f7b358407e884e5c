#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// Angle of R_a^T R_b in radians, accurate down to ~1e-16 (atan2 form, not acos).
double rotation_error(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

// Angle between two translation directions in radians; pi/2 when exactly one is zero.
double translation_error(const Eigen::Vector3d& t_a, const Eigen::Vector3d& t_b);

// max(rotation error, translation error): the pose error behind AUC@5/10/20 (DESIGN.md).
double pose_error(const RelativePose& estimate, const RelativePose& truth);

// Area under the cumulative error curve up to `threshold` (same unit as the errors), normalised
// to [0, 1]: the AUC@5/10/20 degrees of SuperGlue, LoFTR and the paper. A failure counts with an
// error above every threshold (e.g. 180 degrees).
double pose_auc(std::vector<double> errors, double threshold);

}  // namespace hybrid_vo
