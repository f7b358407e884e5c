#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// The final refinement of the hybrid estimator (paper Sec. 4; DESIGN.md "Estimation"): Ceres
// minimises, over R and the unit t, the robust sum of
//  - point: the Sampson error of each point match in pixels, i.e. under F = K2^-T E K1^-1 on pixel
//    coordinates (one row);
//  - VP: the angle between d2 and R d1 as s * (R d1 - d2) when the sign is known, else as
//    s * (d2 x R d1) (three rows of rank two, norm 2 sin(angle / 2) resp. |sin angle|, i.e. the
//    angle for small angles), where s = vp_weight * f and f is the mean focal length of the two
//    cameras: one radian counts as f pixels, the displacement of an image point near the
//    principal point under a rotation by that angle;
//  - line-to-VP: for a segment labelled with VP k, the orthogonal distance of Tardif 2009 in
//    pixels (the distance of an endpoint to the line through the segment's midpoint and the VP)
//    between the segment in image 2 and the VP predicted from image 1, K2 R d1_k, and between the
//    segment in image 1 and the VP predicted from image 2, K1 R^T d2_k (one row per image, times
//    line_vp_weight). Tardif's distance is in pixels and grows with the segment's length, so a
//    long segment, whose direction is better known, weighs more. With refine_vp_directions, a VP
//    with two or more labelled segments per image instead gets a free 3D direction d (camera 1):
//    its segments are measured against K1 d and K2 R d, and its VP residual is dropped (the
//    detected VP was fitted on those same segments).
// Each residual has a Cauchy loss whose scale is given in the
// residual's own unit (pixels or degrees) and is multiplied by the same weight as the residual,
// so the weights do not move the point at which a residual counts as an outlier.
struct FinalRefinementOptions {
  double point_loss_px = 1.0;  // Cauchy scale of the point Sampson residuals, pixels; <= 0: none
  double vp_loss_deg = 2.0;    // Cauchy scale of the VP residuals, degrees; <= 0: none
  // Weight of a VP residual against a point residual: the VP residual is vp_weight * f * angle
  // (f the mean focal length, see above), so 1 counts 1/f rad like 1 px of Sampson error.
  double vp_weight = 1.0;
  // Weight of a line-to-VP residual (Tardif's distance in pixels) against a point residual; its
  // Cauchy scale is point_loss_px.
  double line_vp_weight = 1.0;
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
  // [w, t]. sigma^2 = 2 * final_cost / (rows - 5) is the residual variance in px^2, rows
  // counting two per VP (its three rows have rank two), so the caller need not know the noise
  // level. With the Cauchy loss this sigma^2 is a little low for inliers (about 15 % at noise =
  // half the loss scale) and high when gross outliers remain. Zero and covariance_valid = false
  // when not requested, when there is no point residual (t is then not estimated), when
  // rows <= 5, or when J is rank deficient (singular values below 1e-5 of the largest, e.g. for
  // data that cannot separate t from a rotation).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_valid = false;
  double sigma2 = 0.0;  // the residual variance behind the covariance, px^2
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;  // Ceres' cost, 1/2 sum of the losses, px^2
  // Residuals used: point matches, VP matches, and line-to-VP residuals (up to two per labelled
  // line, one per image).
  int num_point_residuals = 0, num_vp_residuals = 0, num_line_residuals = 0;
  int num_refined_vps = 0;  // VPs whose direction was refined from their segments
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

}  // namespace hybrid_vo
