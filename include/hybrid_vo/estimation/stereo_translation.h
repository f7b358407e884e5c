#pragma once

// The metric translation of a stereo pair whose rotation is known, from the keyframe's stereo
// points seen again: what a rotation-only pair reports in stereo. The two-view translation has
// no length and, when the camera barely moved, no direction either; the stereo points give both,
// and at rest a translation of zero with the covariance of its noise. Each point has an unknown
// inverse depth rho in the keyframe, and
//   keyframe disparity   d  = fx b rho + delta,
//   current left image   x  = pi(R [x_ref; 1] + rho t),
//   current disparity    d' = fx b rho / z + delta   (when known),
// as in estimate_stereo_scale (stereo_scale.h), but with t free in all three directions, so that
// it stays well posed at t = 0 where a scale times a unit direction is not.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/stereo_scale.h"

namespace hybrid_vo {

struct StereoTranslationEstimate {
  bool ok = false;
  Eigen::Vector3d t = Eigen::Vector3d::Zero();  // metres: X_cur = R X_ref + t
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int points = 0;   // usable observations
  int inliers = 0;  // of those, with a Cauchy weight above 1/2 at the end
  double variance_factor = 1.0;
  int iterations = 0;
};

// The sigmas, the loss and the disparity offset come from `options` (every point is used: a far
// one still fixes the translation across its ray); the points count as at most
// `independent_points` independent ones in the covariance (pair_covariance.h). Fewer than
// options.min_near_points usable points, an invalid rig or rotation: not ok.
StereoTranslationEstimate estimate_stereo_translation(
    const Eigen::Matrix3d& R, const StereoRig& rig,
    const std::vector<StereoScaleObservation>& observations, const StereoScaleOptions& options = {},
    double independent_points = 200.0);

}  // namespace hybrid_vo
