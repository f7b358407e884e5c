#pragma once

// The motion of a pair whose data show no translation: the camera turned about its centre, or
// moved too little against the scene's depth for its points to tell. Then every point maps by the
// infinite homography, x2 ~ K2 R K1^-1 x1, a segment's line by its inverse transpose, and a VP by
// d2 = +-R d1 (paper eq. 4): all three modalities fix R, none fixes t, and the five-point model
// has nothing to find (its translation is noise and its rotation inherits the ambiguity).
//
// Two-point RANSAC on the points (rotation_from_two_directions), scored by the transfer error in
// pixels; Gauss-Newton on the inliers of every modality; a covariance that weighs the points and
// segments as pair_covariance.h does (each counts as at most so many independent ones), so that a
// rotation-only pair is as honest as a full one. The transfer residual left over is the pair's
// parallax after the rotation: what a keyframe policy should measure (VINS-Mono compensates the
// rotation before it counts parallax).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/estimation/pair_covariance.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/option_fields.h"

namespace hybrid_vo {

struct RotationOnlyOptions {
  // Inliers: transfer error of a point (pixels, in image 2), distance of a segment's endpoints to
  // its line carried by the rotation (pixels), angle of a VP match (degrees).
  double point_threshold_px = 2.0;
  double line_threshold_px = 2.0;
  double vp_threshold_deg = 2.0;
  double confidence = 0.999;
  int min_iterations = 20;
  int max_iterations = 300;
  int min_point_inliers = 8;  // fewer (and no two inlier VPs): no rotation
  int refine_iterations = 8;
  bool use_lines = true;
  bool use_vps = true;
  uint64_t seed = 0;
};

template <typename Visit>
void visit_fields(RotationOnlyOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(positive(), o.point_threshold_px, o.line_threshold_px, o.vp_threshold_deg,
                  o.max_iterations);
  HYBRID_VO_FIELDS(open_fraction(), o.confidence);
  HYBRID_VO_FIELDS(non_negative(), o.min_iterations, o.min_point_inliers, o.refine_iterations);
  HYBRID_VO_FIELDS(any_value(), o.use_lines, o.use_vps, o.seed);
}

struct RotationOnlyEstimate {
  bool ok = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // X2 = R X1 up to the (unknown) translation
  // Of the left increment R <- exp([w]x) R (camera 2, rad^2), as RelativePoseEstimate's block.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  bool covariance_valid = false;
  std::vector<char> point_inliers, line_inliers, vp_inliers;  // aligned with the matches
  int num_point_inliers = 0, num_line_inliers = 0, num_vp_inliers = 0;
  // Per axis, measured on the inliers (0 where too few): the points' transfer error, the
  // segments' endpoint distance, the VPs' angle (degrees).
  double point_sigma_px = 0.0, line_sigma_px = 0.0, vp_sigma_deg = 0.0;
  // Median transfer error of the point inliers (pixels): the parallax the rotation leaves.
  double parallax_px = 0.0;
  int iterations = 0;
};

// `matches` in undistorted pixels of each camera (lines, VPs and their labels optional); the VP
// signs are tried both ways unless known. `initial` (may be null) is scored as one more
// hypothesis, e.g. the last motion's rotation.
RotationOnlyEstimate estimate_rotation_only(const PinholeCamera& camera1,
                                            const PinholeCamera& camera2,
                                            const TwoViewMatches& matches,
                                            const RotationOnlyOptions& options = {},
                                            const PairCovarianceOptions& honest = {},
                                            const Eigen::Matrix3d* initial = nullptr);

// The transfer error (pixels, image 2) of a point match under a pure rotation R; NaN when the
// point falls behind camera 2 or is not finite.
double rotation_transfer_error_px(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                  const Eigen::Matrix3d& R, const PointMatch& match);

}  // namespace hybrid_vo
