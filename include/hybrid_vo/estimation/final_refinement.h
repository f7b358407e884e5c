#pragma once

#include "hybrid_vo/geometry/option_fields.h"
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// The final refinement of the hybrid estimator (paper Sec. 4; DESIGN.md "Estimation"): Ceres
// minimises, over R and the unit t, the robust sum of whitened residuals, each divided by the
// standard deviation of its modality (ModalityScales: measured on the pair's own inliers), so
// that a modality pulls the pose only as far as its accuracy allows:
//  - point: the Sampson error of each point match in pixels, i.e. under F = K2^-T E K1^-1 on pixel
//    coordinates (one row), over its sigma (per match: points and junctions differ);
//  - VP: the angle between d2 and R d1 as (R d1 - d2) when the sign is known, else as
//    (d2 x R d1) (three rows of rank two, norm 2 sin(angle / 2) resp. |sin angle|, i.e. the angle
//    for small angles), over vp_sigma;
//  - line-to-VP: for a segment labelled with VP k, the orthogonal distance of Tardif 2009 in
//    pixels (the distance of an endpoint to the line through the segment's midpoint and the VP)
//    between the segment in image 2 and the VP predicted from image 1, K2 R d1_k, and between the
//    segment in image 1 and the VP predicted from image 2, K1 R^T d2_k (one row per image), over
//    line_vp_sigma. Tardif's distance grows with the segment's length, so a long segment, whose
//    direction is better known, weighs more. With refine_vp_directions, a VP with two or more
//    labelled segments per image instead gets a free 3D direction d (camera 1): its segments are
//    measured against K1 d and K2 R d, and its VP residual is dropped (the detected VP was fitted
//    on those same segments);
//  - VP prior: a VP whose prior is given (RefinementData::vp_priors) and which has two or more
//    labelled segments in image 2 always gets a free direction d, pulled towards the prior's
//    direction by the prior's covariance (two whitened rows in its tangent plane); camera 1's
//    segments are left out when the prior already holds them. The prior never fixes d.
// The sigmas weight; they do not decide what is an outlier. Points, segments and VPs have a
// Cauchy loss at their modality's inlier threshold (in its own unit, as RANSAC used it), so a
// residual counts as an outlier where it did in RANSAC, whatever the measured noise. A prior has
// none: it passed its gate (the estimator's chi-square test) before it got here, and a robust
// loss would switch it off exactly when the drift it exists to correct has grown.
struct FinalRefinementOptions {
  bool enabled = true;  // false: the RANSAC's (locally optimised) model is the estimate
  // Standard deviations of the modalities. A sigma that is not finite and positive leaves its
  // modality out.
  double point_sigma_px = 1.0 / 3.0;
  double line_vp_sigma_px = 1.0 / 3.0;
  double vp_sigma_deg = 2.0 / 3.0;
  // Cauchy scales (the inlier thresholds); <= 0: plain least squares for that modality.
  double point_loss_px = 1.0;
  double line_vp_loss_px = 2.0;
  double vp_loss_deg = 2.0;
  // Refine the 3D direction of every VP with at least two labelled segments in each image from
  // those segments (image 1 against K1 d, image 2 against K2 R d), instead of trusting the
  // detected VP: the lines then constrain the rotation directly (paper Sec. 4, "lines carry it").
  bool refine_vp_directions = true;
  int max_iterations = 25;
  bool compute_covariance = true;
  // Ceres stopping tolerances (relative cost decrease, relative step). The Cauchy loss makes
  // Levenberg-Marquardt converge linearly (~20x per iteration at 0.5 px noise); at 1e-6 the
  // remaining step is far below the estimate's standard deviation.
  double function_tolerance = 1e-6;
  double parameter_tolerance = 1e-8;
};

template <typename Visit>
void visit_fields(FinalRefinementOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(any_value(), o.enabled, o.point_sigma_px, o.line_vp_sigma_px, o.vp_sigma_deg,
                  o.point_loss_px, o.line_vp_loss_px, o.vp_loss_deg, o.refine_vp_directions,
                  o.compute_covariance);
  HYBRID_VO_FIELDS(non_negative(), o.max_iterations);
  HYBRID_VO_FIELDS(positive(), o.function_tolerance, o.parameter_tolerance);
}

// The refinement's data: inliers of the estimate.
struct RefinementData {
  std::vector<PointMatch> points;      // point-like matches, pixels
  std::vector<double> point_sigma_px;  // per point; empty: FinalRefinementOptions::point_sigma_px
  std::vector<VpMatch> vps;
  std::vector<VpPrior> vp_priors;      // per VP, or empty
  std::vector<LineMatch> lines;        // segments labelled with a VP, pixels
  std::vector<int> line_vp;            // per entry of `lines`: index into `vps`
  // Per VP, or empty (all 1): multiplies the sigmas of its segments and of its VP residual. Must
  // be finite and positive, or the refinement fails.
  std::vector<double> vp_sigma_scale;
};

// The refinement's information by source, at the optimum, for a covariance that weighs the
// sources by what their residuals cannot show (pair_covariance.h). Coordinates: the pose tangent
// [w (3, the left rotation increment), u (2, t = t0 + B u)] followed by two per refined VP
// direction. The points' covariance and the segments' information carry each their own variance
// factor (their whitened residuals' mean square); the priors' none (their covariance is given).
struct InformationSplit {
  bool valid = false;  // the point-like residuals alone fix the pose (their block is invertible)
  Eigen::Matrix<double, 5, 5> points_covariance = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::MatrixXd segment_information;  // segment-to-VP and VP residuals
  Eigen::MatrixXd prior_information;    // the VP priors' rows
  // [w, t] = to_pose [w, u]: identity on w, B on u.
  Eigen::Matrix<double, 6, 5> to_pose = Eigen::Matrix<double, 6, 5>::Zero();
};

struct FinalRefinementResult {
  // False when fewer than 5 residual rows (or fewer independent rows than free parameters, a VP
  // counting two) remain after skipping bad items, when the cameras, the options or the initial
  // pose are not finite and valid (a zero t with points included), or when Ceres fails; the pose
  // then equals the input (t normalised when it can be).
  bool success = false;
  RelativePose pose;  // unit t
  // Covariance of [w, t]: w (3, radians) the left rotation increment R <- exp([w]x) R, and t (3)
  // the unit translation (rank 5: nothing along t). It is sigma^2 (J^T J)^-1, J the Jacobian of
  // the weighted residuals at the optimum scaled by the Cauchy loss (sqrt(rho'), as Ceres does),
  // computed by ceres::Covariance (DENSE_SVD) in the manifolds' tangent spaces and mapped to
  // [w, t]. sigma^2 = 2 * final_cost / (rows - parameters) is the variance of the whitened
  // residuals, rows counting two per VP (its three rows have rank two): 1 when the sigmas are
  // right, and it corrects them when they are not, so the caller need not know the noise level.
  // With the Cauchy loss this sigma^2 is a little low for inliers (about 15 % at noise = half the
  // loss scale) and high when gross outliers remain. Zero and covariance_valid = false
  // when not requested, when there is no point residual (t is then not estimated), when
  // rows <= 5, or when J is rank deficient (singular values below 1e-5 of the largest, e.g. for
  // data that cannot separate t from a rotation).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_valid = false;
  InformationSplit split;  // with the covariance
  double sigma2 = 0.0;  // the variance factor of the whitened residuals behind the covariance
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;  // Ceres' cost, 1/2 sum of the whitened losses
  // Residuals used: point matches, VP matches, and line-to-VP residuals (up to two per labelled
  // line, one per image).
  int num_point_residuals = 0, num_vp_residuals = 0, num_line_residuals = 0;
  int num_refined_vps = 0;  // VPs whose direction was refined from their segments
  int num_vp_priors = 0;    // VPs pulled towards their prior
};

// Refines `initial` on the inliers. Bad items are skipped: non-finite points, VPs with a zero or
// non-finite direction, zero-length or non-finite segments, lines whose label is negative, out of
// range or names a skipped VP (a line_vp shorter than `lines` leaves the rest unlabelled). Without
// point residuals t is left as it is. Single-threaded; Ceres prints nothing.
FinalRefinementResult refine_relative_pose_ceres(
    const PinholeCamera& camera1, const PinholeCamera& camera2,
    const std::vector<PointMatch>& points,  // inlier point-like matches, pixels
    const std::vector<VpMatch>& vps,        // inlier VP matches
    const std::vector<LineMatch>& lines,    // segments labelled with a VP, pixels
    const std::vector<int>& line_vp,        // per entry of `lines`: index into `vps`
    const RelativePose& initial, const FinalRefinementOptions& options = {});

// The same with per-point sigmas and VP priors.
FinalRefinementResult refine_relative_pose_ceres(const PinholeCamera& camera1,
                                                 const PinholeCamera& camera2,
                                                 const RefinementData& data,
                                                 const RelativePose& initial,
                                                 const FinalRefinementOptions& options = {});

}  // namespace hybrid_vo
