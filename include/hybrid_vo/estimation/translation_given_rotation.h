#pragma once

// The translation of a pair whose rotation is known from elsewhere (the map of world
// directions): two-point RANSAC (relpose_known_rotation_2pt) scored by the Sampson error, then
// the direction refined on the inliers. With the rotation held, a plane or a handful of points
// fixes t where the five-point model is degenerate or ambiguous.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

struct TranslationGivenRotationOptions {
  double point_threshold_px = 1.0;  // Sampson error of an inlier
  double confidence = 0.999;
  int min_iterations = 30;
  int max_iterations = 500;
  int min_inliers = 8;  // fewer: no translation
  uint64_t seed = 0;
};

template <typename Visit>
void visit_fields(TranslationGivenRotationOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(positive(), o.point_threshold_px, o.max_iterations);
  HYBRID_VO_FIELDS(open_fraction(), o.confidence);
  HYBRID_VO_FIELDS(non_negative(), o.min_iterations, o.min_inliers);
  HYBRID_VO_FIELDS(any_value(), o.seed);
}

struct TranslationEstimate {
  bool ok = false;
  RelativePose pose;  // the given R, unit t
  std::vector<char> inliers;
  int num_inliers = 0;
  int iterations = 0;
};

// `points` in pixels of each camera; R maps camera-1 to camera-2 coordinates.
TranslationEstimate estimate_translation_given_rotation(
    const PinholeCamera& camera1, const PinholeCamera& camera2,
    const std::vector<PointMatch>& points, const Eigen::Matrix3d& R,
    const TranslationGivenRotationOptions& options = {});

}  // namespace hybrid_vo
