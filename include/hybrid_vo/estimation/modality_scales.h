#pragma once

#include "hybrid_vo/geometry/option_fields.h"
#include <vector>

namespace hybrid_vo {

// How noisy each kind of measurement of one image pair is, measured on its own inliers of the
// best RANSAC model: the final refinement weights every residual by its modality's scale, so
// that a modality pulls the pose only as far as its measured accuracy allows (instead of fixed
// relative weights tuned on a few data sets).
struct ModalityScales {
  double point_px = 0.0;     // Sampson error of point matches, pixels
  double junction_px = 0.0;  // Sampson error of junctions, pixels
  double line_vp_px = 0.0;   // Tardif distance of a labelled segment to its VP, pixels
  double vp_deg = 0.0;       // per-axis angular error of a VP match under the rotation, degrees
  // Residuals behind each scale; 0 when too few were available and the default was used.
  int num_points = 0, num_junctions = 0, num_lines = 0, num_vps = 0;
  // The factor the refinement applied to the point-like sigmas for dependent errors
  // (ModalityScaleOptions::max_independent_points); 1 when it had no more matches than that.
  double point_dependence = 1.0;
};

struct ModalityScaleOptions {
  bool enabled = true;  // false: every modality keeps its default below
  // Fewer residuals than this and the modality keeps its default (or, for junctions, the
  // points' scale): a median of a handful of residuals is too noisy to weight by.
  int min_points = 10, min_junctions = 8, min_lines = 8, min_vps = 2;
  // Residuals count when within this many inlier thresholds (points, junctions: the RANSAC point
  // threshold; segments: line_threshold_px; VPs: the RANSAC VP threshold).
  double inlier_multiple = 3.0;
  double line_threshold_px = 2.0;  // the VP detection's segment threshold
  // Defaults, as fractions of the thresholds: a third, so that the refinement's Cauchy scale of
  // three sigmas falls on the threshold.
  double default_fraction = 1.0 / 3.0;
  // Floors against a scale measured as (nearly) zero from a few exact residuals.
  double min_point_px = 0.05, min_line_px = 0.05, min_vp_deg = 0.005;
  // The residual of a point match shows its own noise, not the errors it shares with its
  // neighbours (KLT's correlated errors, calibration, rolling shutter), which no single pair can
  // measure. Against a VP prior, which carries many frames, the point-like matches therefore
  // weigh what the pair's honest covariance says they know (pair_covariance.h); where it has none,
  // they count as at most this many independent ones (sigma times sqrt(n / this)), in the prior's
  // gate and in the refinement with it. A pair alone keeps the measured sigmas.
  double max_independent_points = 16.0;
};

template <typename Visit>
void visit_fields(ModalityScaleOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(any_value(), o.enabled);
  HYBRID_VO_FIELDS(non_negative(), o.min_points, o.min_junctions, o.min_lines, o.min_vps,
                  o.min_point_px, o.min_line_px, o.min_vp_deg);
  HYBRID_VO_FIELDS(positive(), o.inlier_multiple, o.line_threshold_px, o.default_fraction,
                  o.max_independent_points);
}

// Robust standard deviation per axis of zero-mean Gaussian residuals from their magnitudes: the
// median magnitude over the median of |N(0,1)| (0.6745) for one axis, or over that of a Rayleigh
// variable (sqrt(2 ln 2) = 1.1774) for the length of a two-axis residual. Ignores non-finite
// values; 0 when none is left. `magnitudes` is reordered.
double robust_sigma(std::vector<double>* magnitudes, int axes = 1);

}  // namespace hybrid_vo
