// VisualOdometry's relative scale in mono: each keyframe keeps its points' inverse depths, in the
// odometry's units, triangulated from the pair that made it the keyframe (and carried over from
// the keyframe before, fused); a later pair's translation gets the length that puts those points
// where this frame sees them. Without it every pair's translation had the same length
// (mono_scale), which was right only while the keyframes came at equal distances.
#include <cmath>

#include "vo_frame.h"

namespace hybrid_vo {
namespace {

// The largest standard deviation of the translation's direction (radians).
double translation_direction_sigma(const VisualOdometryResult& r) {
  const double length = r.motion.t.norm();
  if (!(length > 0.0)) return INFINITY;
  const Eigen::Matrix3d C = r.motion_covariance.bottomRightCorner<3, 3>() / (length * length);
  if (!all_finite(C)) return INFINITY;
  return std::sqrt(std::max(0.0, C.trace()));
}

}  // namespace

std::map<int64_t, InverseDepth> VisualOdometry::keyframe_depths(const Frame& f) const {
  std::map<int64_t, InverseDepth> depths;
  const VisualOdometryResult& r = f.result;
  if (f.stereo || !keyframe_.valid || !answered(r.status) || r.status == VoStatus::kFirstFrame ||
      r.status == VoStatus::kReset)
    return depths;
  const TwoViewMatches& m = r.matches;
  const std::vector<char>& inliers = r.estimate.estimate.point_inliers;
  const PinholeCamera& c1 = keyframe_.camera.pinhole;
  const PinholeCamera& c2 = f.input.camera.pinhole;
  const double sigma_n = options_.stereo_scale.point_sigma_px / c2.fx;
  // A translation whose direction is not known to a few degrees (a blank wall's) would place
  // its points anywhere: only those carried over from the keyframe keep a depth then.
  const bool translated = r.motion.t.norm() > 0.0 && r.baseline && r.motion_covariance_valid &&
                          translation_direction_sigma(r) <= options_.mono_depth_max_direction_sigma;
  for (size_t i = 0; i < m.points.size() && i < f.point_ids.size(); ++i) {
    if (!inliers.empty() && (i >= inliers.size() || !inliers[i])) continue;
    const Eigen::Vector2d x1 = c1.normalize(m.points[i].x1), x2 = c2.normalize(m.points[i].x2);
    const auto known = keyframe_.depths.find(f.point_ids[i]);
    InverseDepth depth;
    if (known != keyframe_.depths.end())
      depth = transfer_inverse_depth(r.motion.R, r.motion.t, x1, known->second);
    if (translated)
      depth = fuse_inverse_depths(
          depth, triangulate_inverse_depth(r.motion.R, r.motion.t, x1, x2, sigma_n));
    if (depth.ok) depths[f.point_ids[i]] = depth;
  }
  return depths;
}

bool VisualOdometry::fit_mono_scale(Frame& f, double* scale, double* sigma) const {
  const VisualOdometryResult& r = f.result;
  const TwoViewMatches& m = r.matches;
  const std::vector<char>& inliers = r.estimate.estimate.point_inliers;
  const PinholeCamera& c1 = keyframe_.camera.pinhole;
  const PinholeCamera& c2 = f.input.camera.pinhole;
  // The keyframe's points as a stereo rig of baseline 1 would see them: disparity fx rho, as
  // sure as their triangulation. Only those known to a share of their depth say anything.
  std::vector<StereoScaleObservation> observations;
  for (size_t i = 0; i < m.points.size() && i < f.point_ids.size(); ++i) {
    if (i >= inliers.size() || !inliers[i]) continue;
    const auto known = keyframe_.depths.find(f.point_ids[i]);
    if (known == keyframe_.depths.end()) continue;
    const InverseDepth& d = known->second;
    if (!(d.sigma <= options_.mono_depth_max_sigma * d.rho)) continue;
    StereoScaleObservation o;
    o.x_ref = c1.normalize(m.points[i].x1);
    o.disparity_ref = c1.fx * d.rho;
    o.disparity_ref_sigma_px = c1.fx * d.sigma;
    o.x_cur = c2.normalize(m.points[i].x2);
    observations.push_back(o);
  }
  // A few hundred points fix a length to a fraction of a percent; more cost without telling more
  // (their errors are shared), so every k-th is taken.
  constexpr size_t kMaxPoints = 200;
  if (observations.size() > kMaxPoints) {
    std::vector<StereoScaleObservation> every;
    const double step = static_cast<double>(observations.size()) / kMaxPoints;
    for (size_t k = 0; k < kMaxPoints; ++k) every.push_back(observations[static_cast<size_t>(k * step)]);
    observations = std::move(every);
  }
  StereoScaleOptions options = options_.stereo_scale;
  options.max_depth_baselines = 0.0;
  options.disparity_offset_px = options.disparity_offset_sigma_px = 0.0;
  options.refine_motion = false;
  const StereoRig rig{c1.fx, c1.fy, 1.0};
  const StereoScaleEstimate fit = estimate_stereo_scale(f.oriented.scale_pose, rig, observations,
                                                        options);
  f.result.mono_scale_points = fit.status == StereoScaleStatus::kOk ? fit.inliers : 0;
  // Most points must agree: where a few do (a blank wall's handful, or depths from a pair whose
  // translation was wrong), their scale is one of several (plain corridor 1: 5 of 29 points gave
  // twice the length, and every later pair inherits it).
  if (fit.status != StereoScaleStatus::kOk ||
      fit.inliers < std::max(options_.stereo_scale.min_near_points,
                             static_cast<int>(std::ceil(0.5 * fit.near_points))))
    return false;
  *scale = fit.scale;
  // As the stereo scale's: its points share their errors, so they count as at most the
  // translation's independent points.
  *sigma = fit.sigma * std::sqrt(std::max(1.0, fit.near_points /
                                                   pair_options().covariance.independent_translation_points));
  return true;
}

}  // namespace hybrid_vo
