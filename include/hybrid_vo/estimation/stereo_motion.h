#pragma once

// The metric motion of a stereo pair from the keyframe's stereo points seen again: what a pair
// without a baseline reports in stereo. Its two-view translation has no length and, when the
// camera barely moved, no direction either, and a rotation fitted alone takes in whatever
// translation the points cannot show (a camera turning about a point behind it); the stereo
// points fix both, at any baseline, and at rest give a translation of zero with the covariance of
// its noise. Each point has an unknown inverse depth rho in the keyframe, and
//   keyframe disparity   d  = fx b rho + delta,
//   current left image   x  = pi(R [x_ref; 1] + rho t),
//   current disparity    d' = fx b rho / z + delta   (when known),
// as in estimate_stereo_scale (stereo_scale.h), but with t free in all three directions (well
// posed at t = 0, where a scale times a unit direction is not) and R refined from its start.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/stereo_scale.h"

namespace hybrid_vo {

struct StereoMotionEstimate {
  bool ok = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // X_cur = R X_ref + t, t in metres
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  // Of [w, t], w the left increment R <- exp([w]x) R (rad), t in metres; the rotation block is
  // zero when the rotation was held.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  int points = 0;   // usable observations
  int inliers = 0;  // of those, with a Cauchy weight above 1/2 at the end
  double variance_factor = 1.0;
  int iterations = 0;
};

// From the rotation R (held unless refine_rotation) and t = 0. The sigmas, the loss and the
// disparity offset come from `options` (every point is used: a far one still fixes the motion
// across its ray); the points count as at most `independent_points` independent ones in the
// covariance (pair_covariance.h). Fewer than options.min_near_points usable points, an invalid
// rig or rotation: not ok.
StereoMotionEstimate estimate_stereo_motion(const Eigen::Matrix3d& R, const StereoRig& rig,
                                            const std::vector<StereoScaleObservation>& observations,
                                            const StereoScaleOptions& options = {},
                                            double independent_points = 200.0,
                                            bool refine_rotation = true);

}  // namespace hybrid_vo
