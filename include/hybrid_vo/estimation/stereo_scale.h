#pragma once

// Metric scale of a frame-to-frame motion from a rectified stereo camera: the two-view estimate
// has a unit translation t, and the motion is (R, s t). The scale s is fitted where the noise
// lives, in the disparities and in the current image, not to triangulated depths: depth f b / d
// is biased upward by disparity noise when d is a few pixels, and a median of per-point scales,
// in which every point counts the same, inherits that bias (issue 17).

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// Focal lengths of the rectified left camera (pixels) and the baseline to the right camera.
struct StereoRig {
  double fx = 0.0, fy = 0.0;
  double baseline_m = 0.0;
  bool valid() const;
};

// One point seen in the keyframe's stereo pair and again in the current frame's left image.
struct StereoScaleObservation {
  Eigen::Vector2d x_ref = Eigen::Vector2d::Zero();  // keyframe, left, normalised (K^-1 x)
  double disparity_ref = 0.0;                       // keyframe disparity, pixels (> 0)
  Eigen::Vector2d x_cur = Eigen::Vector2d::Zero();  // current frame, left, normalised
  double disparity_cur = 0.0;                       // current disparity, pixels; <= 0: unknown
  // The keyframe disparity's own noise (pixels); <= 0: the options' disparity_sigma_px. A
  // monocular keyframe's depths come from a pair's triangulation, each as sure as its parallax.
  double disparity_ref_sigma_px = 0.0;
};

struct StereoScaleOptions {
  // Noise of a disparity and of a tracked point in the current image (pixels): they weigh the
  // two kinds of residual against each other; the overall level is estimated from the fit. On
  // the rendered corridor, against exact depths, the disparities and the node's current points
  // are about equally precise (robust sigma of near points 0.17 and 0.17 px along the flow with
  // the affine refinement, of far ones 0.11 and 0.14 px); the KLT tracker's own near points were
  // twice as noisy along their flow (0.34 px), for which 0.5 px was set.
  double disparity_sigma_px = 0.3;
  double point_sigma_px = 0.3;
  // Only points closer than this many baselines constrain the scale (ORB-SLAM2's "close" stereo
  // points use 35-40): farther, a disparity of a few pixels says little about depth and any
  // calibration or matching bias of a tenth of a pixel dominates it. 0: no limit.
  double max_depth_baselines = 40.0;
  int min_near_points = 10;  // fewer usable near points: no scale (status kTooFewNearPoints)
  // Cauchy loss on each point's whitened residual norm, in standard deviations: a wrong stereo
  // or temporal match is down-weighted instead of pulling the scale.
  double loss_scale = 3.0;
  int max_iterations = 30;
  // One disparity offset shared by all points, d = fx b rho + delta: a prior (mean, sigma);
  // sigma 0 keeps delta at the mean, infinity leaves it free.
  double disparity_offset_px = 0.0;
  double disparity_offset_sigma_px = 0.0;
  // Let the rotation and the translation direction move in the fit too.
  bool refine_motion = false;
};

enum class StereoScaleStatus {
  kOk,
  kInvalidInput,      // rig or motion not usable (no translation, non-finite)
  kTooFewNearPoints,  // fewer than min_near_points usable observations within the depth limit
  kNoConvergence,     // the fit diverged or left the scale non-positive
};
const char* to_string(StereoScaleStatus status);

struct StereoScaleEstimate {
  StereoScaleStatus status = StereoScaleStatus::kInvalidInput;
  double scale = 0.0;            // metres per unit of t (the metric motion is R, scale * t)
  double sigma = 0.0;            // standard deviation of scale (metres), from the fit
  int near_points = 0;           // usable observations within the depth limit
  int inliers = 0;               // of those, with a Cauchy weight above 1/2 at the end
  int iterations = 0;
  double variance_factor = 1.0;  // weighted residual variance over the modelled one
  double disparity_offset = 0.0; // pixels, when estimated
  double offset_sigma = 0.0;
  RelativePose motion;           // the motion of the fit (unit t), refined or as given
};

// Maximum-likelihood scale (viso2's idea of fitting the motion where the measurements are):
// each near point i has an unknown inverse depth rho_i in the keyframe, and
//   keyframe disparity   d_i  = fx b rho_i,
//   current left image   x_i  = pi(R [x_ref; 1] + s rho_i t),
//   current disparity    d'_i = fx b rho_i / z_i   (when known; z_i the depth ratio above),
// with the noise of options. The rho_i are eliminated per point (Schur complement), so the fit
// is a Gauss-Newton in s alone with Cauchy reweighting of each point; the sigma is that of the
// reduced normal equation times the variance factor. Starts from the median of per-point
// scales. `unit_motion` is the two-view estimate (any non-zero t; the scale is for t as given).
StereoScaleEstimate estimate_stereo_scale(const RelativePose& unit_motion, const StereoRig& rig,
                                          const std::vector<StereoScaleObservation>& observations,
                                          const StereoScaleOptions& options = {});

// The estimator before issue 17, the baseline for eval_stereo_scale and the tests: every point's
// own scale from its triangulated depth Z = fx b / d (only points closer than max_depth_baselines
// when > 0), median over the points. NaN with fewer than 5 usable points.
double median_of_point_scales(const RelativePose& unit_motion, const StereoRig& rig,
                              const std::vector<StereoScaleObservation>& observations,
                              double max_depth_baselines = 0.0);

// Self-calibration of a constant disparity offset (a right camera whose principal point or
// rectification is off by a pixel: the shared KITTI 01 stereo set reads about -1 px, which makes
// every depth at 20-40 baselines 3-6 % too long). Each pair's free-offset fit (all points, the
// motion refined) gives delta with its sigma; they are averaged over pairs with exponential
// forgetting and a per-pair spread tau, and the offset is applied only once it is both larger
// than the dead band and several sigma from zero, so a calibrated rig keeps delta = 0.
struct DisparityOffsetOptions {
  bool enabled = true;
  double forgetting = 0.99;     // weight of the past per pair
  double pair_spread_px = 0.2;  // tau: pair-to-pair spread of delta beyond its fitted sigma
  double dead_band_px = 0.5;    // smaller offsets are not applied
  double significance = 3.0;    // |mean| must exceed this many of its sigmas
};

class DisparityOffsetFilter {
 public:
  explicit DisparityOffsetFilter(const DisparityOffsetOptions& options = {}) : options_(options) {}
  // One pair's observations (as for estimate_stereo_scale); false when the fit failed.
  bool update(const RelativePose& unit_motion, const StereoRig& rig,
              const std::vector<StereoScaleObservation>& observations,
              const StereoScaleOptions& scale_options = {});
  // The offset to apply (pixels; 0 until it is significant) and the filtered mean and sigma.
  double offset() const;
  double mean() const { return sum_w_ > 0.0 ? sum_wd_ / sum_w_ : 0.0; }
  double sigma() const;
  int pairs() const { return pairs_; }
  void reset() { sum_w_ = sum_wd_ = 0.0; pairs_ = 0; }

 private:
  DisparityOffsetOptions options_;
  double sum_w_ = 0.0, sum_wd_ = 0.0;
  int pairs_ = 0;
};

// The 6x6 covariance of [rotation (left increment, rad), metric translation s t] from the
// estimator's covariance of [rotation, unit t] and an independent scale with standard
// deviation sigma_s: s^2 Cov(t) + sigma_s^2 t t^T, the cross terms times s.
Eigen::Matrix<double, 6, 6> metric_motion_covariance(const Eigen::Matrix<double, 6, 6>& unit,
                                                     const Eigen::Vector3d& unit_t, double scale,
                                                     double sigma_scale);

}  // namespace hybrid_vo
