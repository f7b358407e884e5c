// VisualOdometry's relative scale in mono: each keyframe keeps its points' inverse depths, in the
// odometry's units, triangulated from the pair that made it the keyframe (and carried over from
// the keyframe before, fused); a later pair's translation gets the length that puts those points
// where this frame sees them. Without it every pair's translation had the same length
// (mono_scale), which was right only while the keyframes came at equal distances. Every pair with
// a baseline refines its keyframe's depths (as SVO's depth filter refines its seeds with every
// frame), so that a keyframe that knew none, the first, knows them after its first baseline; a
// pair without one takes its translation from them (issue 58).
#include <algorithm>
#include <cmath>
#include <utility>

#include "hybrid_vo/estimation/stereo_motion.h"

#include "vo_frame.h"

namespace hybrid_vo {
namespace {

constexpr int kLooseMinPoints = 100;

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

std::vector<StereoScaleObservation> VisualOdometry::depth_observations(const Frame& f) const {
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
  return observations;
}

StereoScaleOptions VisualOdometry::depth_fit_options() const {
  // The depths are the keyframe's own (no depth limit, no disparity offset); the pose stays the
  // pair's.
  StereoScaleOptions options = options_.stereo_scale;
  options.max_depth_baselines = 0.0;
  options.disparity_offset_px = options.disparity_offset_sigma_px = 0.0;
  options.refine_motion = false;
  return options;
}

bool VisualOdometry::fit_mono_scale(Frame& f, double* scale, double* sigma) const {
  // A direction that is not known to several degrees (a blank wall's: 57 degrees on the white
  // panels) fits any length to the depths: 17 times the last pair's there, where the truth had
  // 1.5; the caller's fallback, the last pair's speed, is surer.
  const double direction =
      std::sqrt(std::max(0.0, f.unit_covariance.bottomRightCorner<3, 3>().trace()));
  if (!(direction <= kLooseDirectionFactor * options_.mono_depth_max_direction_sigma))
    return false;
  const std::vector<StereoScaleObservation> observations = depth_observations(f);
  const PinholeCamera& c1 = keyframe_.camera.pinhole;
  const StereoRig rig{c1.fx, c1.fy, 1.0};
  const StereoScaleEstimate fit = estimate_stereo_scale(f.oriented.scale_pose, rig, observations,
                                                        depth_fit_options());
  f.result.mono_scale_points = fit.status == StereoScaleStatus::kOk ? fit.inliers : 0;
  // Most points must agree: where a few do (a blank wall's handful, or depths from a pair whose
  // translation was wrong), their scale is one of several (plain corridor 1: 5 of 29 points gave
  // twice the length, and every later pair inherits it).
  if (fit.status != StereoScaleStatus::kOk ||
      fit.inliers < std::max(options_.mono_min_depth_points,
                             static_cast<int>(std::ceil(0.5 * fit.near_points))))
    return false;
  *scale = fit.scale;
  // As the stereo scale's: its points share their errors, so they count as at most the
  // translation's independent points.
  *sigma = fit.sigma * std::sqrt(std::max(1.0, fit.near_points /
                                                   pair_options().covariance.independent_translation_points));
  return true;
}

double VisualOdometry::mono_length_without_depths(const Frame& f, double* sigma) {
  // The last pair's speed, or before any (the first keyframe) a length that goes with the
  // parallax after the rotation, about fx |t| times the points' inverse depth: the first such
  // pair's is the unit, mono_scale (before, every pair of the first keyframe had mono_scale until
  // its direction was sure enough to triangulate: 40 frames of a slow hand-held camera). Not
  // beyond the first keyframe: with parallaxes of 2-7 px the noise's share of the first pair's
  // shrank each keyframe's unit against the last (the white panels' lengths fell twentyfold).
  // Either is a guess, known to a factor of about e^0.5; only the very first length is exact,
  // being the unit.
  constexpr double kGuessSigma = 0.5;
  const double dt = f.input.stamp - keyframe_.stamp;
  if (mono_speed_ > 0.0 && dt > 0.0) {
    *sigma = kGuessSigma * mono_speed_ * dt;
    return mono_speed_ * dt;
  }
  if (keyframe_.unit_parallax > 0.0 && f.parallax > 0.0) {
    const double length = keyframe_.unit_length * f.parallax / keyframe_.unit_parallax;
    *sigma = kGuessSigma * length;
    return length;
  }
  if (f.parallax > 0.0) {
    keyframe_.unit_parallax = f.parallax;
    keyframe_.unit_length = options_.mono_scale;
  }
  *sigma = 0.0;
  return options_.mono_scale;
}

bool VisualOdometry::measure_mono_translation(Frame& f) const {
  VisualOdometryResult& r = f.result;
  const std::vector<StereoScaleObservation> observations = depth_observations(f);
  const PinholeCamera& c1 = keyframe_.camera.pinhole;
  const StereoRig rig{c1.fx, c1.fy, 1.0};
  // The rotation that explains the points is held (the pair's; the published one stays the
  // oriented pose's), so that only the translation is measured: at rest zero within the points'
  // noise. Its covariance is that of a fit with the rotation free as well: a rotation that is off
  // moves every point as a translation would, and a pair without a baseline barely tells the two
  // apart (held, the hand-held room's 22 such pairs had a direction NEES of 21). The points share
  // their errors as a baseline's direction does: they count as at most the translation's
  // independent points.
  const double independent = pair_options().covariance.independent_translation_points;
  const StereoMotionEstimate m = estimate_stereo_motion(
      f.oriented.scale_pose.R, rig, observations, depth_fit_options(), independent, false);
  const StereoMotionEstimate free = estimate_stereo_motion(
      f.oriented.scale_pose.R, rig, observations, depth_fit_options(), independent, true);
  // Most points must agree, as for the length of a pair with a baseline.
  if (!m.ok || !free.ok || !all_finite(m.t) || !all_finite(free.covariance) ||
      m.inliers < std::max(options_.mono_min_depth_points,
                           static_cast<int>(std::ceil(0.5 * m.points))))
    return false;
  r.motion.t = m.t;
  r.motion_covariance.bottomRightCorner<3, 3>() = free.covariance.bottomRightCorner<3, 3>();
  r.motion_covariance.topRightCorner<3, 3>().setZero();
  r.motion_covariance.bottomLeftCorner<3, 3>().setZero();
  r.mono_scale_points = m.inliers;
  r.translation_from_depths = true;
  return true;
}

void VisualOdometry::refine_keyframe_depths(const Frame& f) {
  const VisualOdometryResult& r = f.result;
  // A keyframe that knew no depths as it was made (the first one, after a blank wall) takes them
  // from a pair whose direction is less sure, given many points: their errors are alike (a
  // direction that is off stretches them all), so the lengths fitted to them keep one unit. The
  // hand-held room's first keyframe (a few hundred points) knew its depths 35 frames earlier so
  // (ATE 0.034 -> 0.015 m); the white panels' (20-35 points) got depths that gave worse lengths
  // than the last pair's speed (ATE 0.035 -> 0.054 m).
  const double direction = translation_direction_sigma(r);
  const bool loose = direction > options_.mono_depth_max_direction_sigma;
  if (f.stereo || !r.baseline || !r.motion_covariance_valid || !(r.motion.t.norm() > 0.0) ||
      (loose && (!keyframe_.made_depths.empty() ||
                 !(direction <= kLooseDirectionFactor * options_.mono_depth_max_direction_sigma))))
    return;
  const TwoViewMatches& m = r.matches;
  const std::vector<char>& inliers = r.estimate.estimate.point_inliers;
  const PinholeCamera& c1 = keyframe_.camera.pinhole;
  const PinholeCamera& c2 = f.input.camera.pinhole;
  const double sigma_n = options_.stereo_scale.point_sigma_px / c2.fx;
  // Each point triangulated in the keyframe (the pair turned around: its second camera is the
  // keyframe). A point keeps one pair's triangulation, replaced only by one at least twice as
  // sure (fusing them all would count the keyframe's own sighting, which they share, again with
  // each pair). Each replacement hands the pair's length on to the keyframe's unit, with its
  // error: replaced at every frame, the hand-held room's unit wandered by 7 % over one keyframe;
  // twice as sure, a point is replaced two or three times as its parallax grows.
  constexpr double kSurer = 0.5;
  const RelativePose back = RelativePose(r.motion.R, r.motion.t).inverse();
  std::vector<std::pair<int64_t, InverseDepth>> found;
  int usable = 0;
  for (size_t i = 0; i < m.points.size() && i < f.point_ids.size(); ++i) {
    if (i >= inliers.size() || !inliers[i]) continue;
    const InverseDepth d = triangulate_inverse_depth(back.R, back.t, c2.normalize(m.points[i].x2),
                                                     c1.normalize(m.points[i].x1), sigma_n);
    if (!d.ok) continue;
    found.emplace_back(f.point_ids[i], d);
    usable += d.sigma <= options_.mono_depth_max_sigma * d.rho;
  }
  if (loose && usable < kLooseMinPoints) return;
  const int triangulated = static_cast<int>(found.size());
  int replaced = 0;
  for (const auto& [id, d] : found) {
    const auto best = keyframe_.pair_depths.find(id);
    if (best != keyframe_.pair_depths.end() && !(d.sigma < kSurer * best->second.sigma)) continue;
    ++replaced;
    keyframe_.pair_depths[id] = d;
    const auto made = keyframe_.made_depths.find(id);
    keyframe_.depths[id] =
        made == keyframe_.made_depths.end() ? d : fuse_inverse_depths(made->second, d);
  }
  // The unit's log-scale takes the pair's relative length error, in the share of the points
  // that took its length (PoseCovarianceChain: the unit's drift is the seventh state).
  if (replaced > 0 && f.length > 0.0) {
    keyframe_.pose_covariance(6, 6) += static_cast<double>(replaced) / triangulated *
                                       (f.length_variance() + f.direction_variance());
  }
}

}  // namespace hybrid_vo
