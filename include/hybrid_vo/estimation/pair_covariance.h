#pragma once

// The covariance a pair reports, from what its own data show and what they cannot.
//
// The refinement's covariance, sigma^2 (J^T J)^-1, treats every residual as independent. Against
// exact truth (rendered corridors) and on real data it claims 3-15 times less than the pair's
// error in sigma (doc/consistency.md): the pair's residuals cannot show the errors that all its
// matches share (KLT's correlated errors, calibration, rolling shutter: the rotation absorbs
// them), nor a second model the data fit almost as well (a plane's two motions, the points of a
// blank wall), which a local curvature never sees. So the sources are weighed apart:
//  - the point-like matches count as at most `independent_points` independent ones;
//  - the segments and VPs as at most `independent_segments` (a VP's segments share its error);
//  - the VP priors as they are (their covariance is the map's, kept honest there);
//  - the poses of RANSAC's competing hypotheses (rotation and translation direction together: a
//    short baseline trades one for the other), weighted by their likelihood with the points
//    counting as `ambiguity_independent_points`, add their spread to the points' covariance.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/final_refinement.h"
#include "hybrid_vo/geometry/option_fields.h"

namespace hybrid_vo {

struct PairCovarianceOptions {
  // false: the refinement's covariance as it is.
  bool enabled = true;
  double independent_points = 200.0;
  // For the translation direction, fewer: its signal is the parallax of a few pixels, and what
  // the points share (a KLT track's lag along its flow, which grows with the flow) moves it more
  // than the rotation. Chosen on the rendered corridors (seeds 1-3), a 30 Hz room and the
  // ramp from rest; direction NEES medians 1.0-2.1 there (7-15 with 200).
  double independent_translation_points = 30.0;
  double independent_segments = 10.0;
  double ambiguity_independent_points = 20.0;
  // RANSAC keeps the hypotheses within this much of its best cost (a point-like match costs at
  // most 1), the cheapest `max_hypotheses` of them.
  double hypothesis_margin = 60.0;
  int max_hypotheses = 64;
  // An error every point of a pair shares (pixels per axis): no number of points averages it
  // away, and it moves the image as a rotation does. A camera at rest and pans over photographs
  // (exact truth) are about 0.016 px off in their rotation (0.002 degrees at f = 460 px, 0.001 at
  // 1000 px) where hundreds of points claim a tenth of it: KLT's own bias, the same for tracks
  // through the same images. Chosen on a rendered room at rest and the eight Herz-Jesu pans
  // (rotation NEES medians 2.2 and 0.9-1.6), checked on the eleven fountain pans (0.5-1.4).
  double shared_error_px = 0.008;
};

template <typename Visit>
void visit_fields(PairCovarianceOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(any_value(), o.enabled);
  HYBRID_VO_FIELDS(positive(), o.independent_points, o.independent_translation_points,
                  o.independent_segments, o.ambiguity_independent_points);
  HYBRID_VO_FIELDS(non_negative(), o.hypothesis_margin, o.max_hypotheses, o.shared_error_px);
}

// A competing pose X2 = R X1 + t and its RANSAC cost; t unit, or zero when not known.
struct PoseHypothesis {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  double cost = 0.0;
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};

// The spread of the hypotheses' rotations about R (rad^2, left increment), each weighted by
// exp(-(cost - best_cost) / temperature) and R itself by 1: sum w d d^T / (1 + sum w).
// Non-finite hypotheses are skipped; none gives zero.
Eigen::Matrix3d rotation_spread(const std::vector<PoseHypothesis>& hypotheses,
                                const Eigen::Matrix3d& R, double best_cost, double temperature);

// The same weights over the joint tangent [w, u] of the pose (R, unit t), u = B^T d with d the
// hypothesis' direction (of either sign, the nearer) on the sphere's tangent plane at t and B
// (3x2) that plane's basis (InformationSplit::to_pose): 5x5, its top-left block rotation_spread.
// A hypothesis without a translation adds its rotation only.
Eigen::Matrix<double, 5, 5> pose_spread(const std::vector<PoseHypothesis>& hypotheses,
                                        const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                        const Eigen::Matrix<double, 3, 2>& B, double best_cost,
                                        double temperature);

// The temperature for rotation_spread and pose_spread. RANSAC's cost counts a residual r as (r / threshold)^2, so
// a likelihood ratio of Gaussian matches with noise sigma is exp(-cost (threshold / sigma)^2 / 2);
// with `matches` of them worth `independent` ones it is tempered by matches / independent:
// temperature = 2 (sigma / threshold)^2 max(1, matches / independent).
double hypothesis_temperature(double matches, double independent, double sigma_px,
                              double threshold_px);

// [w, t] covariance (6x6, like FinalRefinementResult::covariance) of the pair from the
// refinement's split, the competing poses' spread (pose_spread, in the split's tangent), the
// numbers of point-like matches and of labelled segments: ((g_p C_p + A)^-1 + I_s / g_s +
// I_prior)^-1 with the VP directions marginalised, g = max(1, count / independent). Zero and
// false when the split is invalid or the result is not a covariance.
bool pair_covariance(const InformationSplit& split, const Eigen::Matrix<double, 5, 5>& spread,
                     double point_matches, double segments,
                     const PairCovarianceOptions& options, Eigen::Matrix<double, 6, 6>* covariance);

}  // namespace hybrid_vo
