#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

struct RelativePoseRefinementOptions {
  int max_iterations = 20;
  // Cauchy loss scale in normalised units (pixels / f); 0 means plain least squares.
  double loss_scale = 0.0;
  // Weight of a VP residual (sin of the angle between v2 and +-R v1) against a Sampson error in
  // normalised units: 1 treats 1e-3 rad like 1 px at f = 1000.
  double vp_weight = 1.0;
  // VP matches with v2 = +R v1 exactly; otherwise the residual ignores the sign.
  bool vp_signs_known = false;
  // Stop when the relative decrease of the cost falls below this.
  double function_tolerance = 1e-12;
};

struct RelativePoseRefinementSummary {
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
};

// Levenberg-Marquardt on the Sampson errors of point matches plus VP alignment residuals, in
// normalised coordinates, over R (left so(3) increment) and the unit t (two tangent directions).
// This is the local optimisation of the paper's Sec. 4 and supp. Fig. 5; the final Ceres
// refinement with covariance builds on the same residuals. The pose is left unchanged when there
// are fewer than five residual rows or the data are not finite.
RelativePoseRefinementSummary refine_relative_pose(
    const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2,
    const std::vector<Eigen::Vector3d>& v1, const std::vector<Eigen::Vector3d>& v2,
    const RelativePoseRefinementOptions& options, RelativePose* pose);

// Sampson error of a point match under the essential matrix E, in normalised units.
double sampson_error(const Eigen::Matrix3d& E, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2);

}  // namespace hybrid_vo
