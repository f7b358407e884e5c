// VisualOdometry's stereo scale: the stereo pyramids and points of each frame (and, first, the
// keyframe's pending ones), matched beside the estimator; the scale's observations (the
// keyframe's stereo points among the pose's inliers, seen again, refined, with this frame's
// disparities); and the fit under the self-calibrated disparity offset.
#include <algorithm>
#include <chrono>
#include <limits>

#include "hybrid_vo/features/vignetting.h"
#include "vo_frame.h"

namespace hybrid_vo {

std::map<int64_t, Eigen::Vector3d> VisualOdometry::StereoFeatures::points() const {
  std::map<int64_t, Eigen::Vector3d> points3d;
  if (!matcher) return points3d;
  std::vector<char> valid;
  const std::vector<Eigen::Vector3d> X = matcher->points(&valid);
  for (size_t i = 0; i < ids.size(); ++i)
    if (valid[i]) points3d[ids[i]] = X[i];
  return points3d;
}

void VisualOdometry::build_stereo_pyramids(Frame& f) const {
  f.pair.right = stereo_pyramid(flat_field(GrayImage(f.input.right_image).mat(), f.flat_field_gain),
                                options_.stereo);
  if (!f.klt_pyramid) f.pair.left = stereo_pyramid(f.gray.mat(), options_.stereo);
}

void VisualOdometry::start_stereo(Frame& f) {
  // Stereo points of this frame's features, for the scale of this and the next motion, on the
  // second thread while this one estimates (the few frames whose estimate fails cancel them).
  // KLT tracking matches its tracks and, first, the keyframe's new features tracked into this
  // frame (Keyframe::stereo_pending); other points are matched at once.
  if (!f.stereo || f.stereo_started) return;
  f.stereo_started = true;
  f.pyramids_job.get();
  if (f.tracking) complete_keyframe_stereo(f.points, &f.stereo_clock);
  f.current_stereo =
      stereo_features(f.pair, f.points, f.input.external.has_points || f.tracking);
  StereoMatcher& matcher = *f.current_stereo.matcher;
  f.stereo_loop = worker_->share(matcher.chunks(),
                                 f.stereo_clock.timed([&matcher](int c) { matcher.search(c); }));
}

void VisualOdometry::finish_stereo(Frame& f) {
  if (!f.stereo || f.stereo_finished) return;
  start_stereo(f);
  f.stereo_loop.join();
  f.result.stages.stereo_ms = f.stereo_clock.ms();
  f.points3d = f.current_stereo.points();
  f.stereo_finished = true;
}

VisualOdometry::StereoFeatures VisualOdometry::stereo_features(
    const StereoPair& pair, const std::map<int64_t, Eigen::Vector2d>& points, bool predict) const {
  StereoFeatures stereo;
  std::vector<Eigen::Vector2d> pixels;
  // A track's disparity in the keyframe (usually the previous frame) is where its search starts
  // (descriptor features have no tracks: their ids are indices into one frame).
  std::vector<double> predicted;
  const double fx_baseline = keyframe_.camera.pinhole.fx * pair.baseline_m;
  for (const auto& [id, p] : points) {
    stereo.ids.push_back(id);
    pixels.push_back(p);
    const auto it = keyframe_.valid && predict ? keyframe_.points3d.find(id)
                                               : keyframe_.points3d.end();
    predicted.push_back(it != keyframe_.points3d.end() ? fx_baseline / it->second.z()
                                                        : std::numeric_limits<double>::quiet_NaN());
  }
  stereo.matcher = std::make_unique<StereoMatcher>(pair.left, pair.right, std::move(pixels),
                                                   pair.camera, pair.baseline_m, options_.stereo,
                                                   std::move(predicted));
  return stereo;
}

void VisualOdometry::complete_keyframe_stereo(const std::map<int64_t, Eigen::Vector2d>& tracked,
                                              WorkClock* clock) {
  std::map<int64_t, Eigen::Vector2d> late;
  for (const int64_t id : keyframe_.stereo_pending)
    if (tracked.count(id)) late[id] = keyframe_.points.at(id);
  keyframe_.stereo_pending.clear();
  if (late.empty() || !keyframe_.stereo.valid()) return;
  // New features had no disparity to start from: no prediction, as when they were new.
  const StereoFeatures stereo = stereo_features(keyframe_.stereo, late, false);
  worker_->parallel_for(stereo.matcher->chunks(),
                        clock->timed([&](int chunk) { stereo.matcher->search(chunk); }));
  for (const auto& [id, X] : stereo.points()) keyframe_.points3d[id] = X;
}

void VisualOdometry::observe_scale(Frame& f) const {
  // This thread refines the current points while the second one still matches the stereo
  // points (then it re-detects, and joins in once free).
  const auto refine_start = std::chrono::steady_clock::now();
  if (f.stereo) f.scale_observations = scale_observations(f, &f.observed);
  f.result.stages.scale_ms = ms_since(refine_start);
}

std::vector<StereoScaleObservation> VisualOdometry::scale_observations(
    const Frame& f, std::vector<int64_t>* observed) const {
  const TwoViewMatches& m = f.result.matches;
  const std::vector<char>& inliers = f.result.estimate.estimate.point_inliers;
  std::vector<StereoScaleObservation> observations;
  std::vector<int64_t>& ids = *observed;
  ids.clear();
  // The points were triangulated as Z = fx b / d.
  const double fx_baseline = keyframe_.camera.pinhole.fx * f.input.baseline_m;
  for (size_t i = 0; i < m.points.size() && i < f.point_ids.size(); ++i) {
    if (i >= inliers.size() || !inliers[i]) continue;
    const auto it = keyframe_.points3d.find(f.point_ids[i]);
    if (it == keyframe_.points3d.end()) continue;
    StereoScaleObservation o;
    o.x_ref = keyframe_.camera.pinhole.normalize(m.points[i].x1);
    o.disparity_ref = fx_baseline / it->second.z();
    o.x_cur = f.input.camera.pinhole.normalize(m.points[i].x2);
    observations.push_back(o);
    ids.push_back(f.point_ids[i]);
  }
  if (!f.tracking || !options_.stereo_refine_tracks || keyframe_.image.empty())
    return observations;
  return refine_scale_points(f, &ids, std::move(observations));
}

std::vector<StereoScaleObservation> VisualOdometry::refine_scale_points(
    const Frame& f, std::vector<int64_t>* observed,
    std::vector<StereoScaleObservation> observations) const {
  const std::vector<int64_t>& ids = *observed;
  // Only the points that can scale the motion, nearer than the fit's depth limit with a margin
  // for the disparity offset: a farther point moves and grows little between frames (on the
  // rendered corridor the tracker's lag beyond 40 baselines is 0.001 px), and on a highway most
  // points are far. In the distorted images, where the tracker's points are.
  const double limit = options_.stereo_scale.max_depth_baselines;
  const double min_disparity = limit > 0.0 ? 0.5 * keyframe_.camera.pinhole.fx / limit : 0.0;
  std::vector<size_t> near;
  std::vector<Eigen::Vector2d> from, to;
  for (size_t k = 0; k < ids.size(); ++k) {
    if (observations[k].disparity_ref < min_disparity) continue;
    near.push_back(k);
    from.push_back(keyframe_.points.at(ids[k]));
    to.push_back(f.points.at(ids[k]));
  }
  // On both threads, in chunks (each point is refined on its own: the same result either way).
  constexpr int kChunk = 16;
  const int n = static_cast<int>(from.size());
  std::vector<char> refined(n, 0);
  worker_->parallel_for((n + kChunk - 1) / kChunk, [&](int chunk) {
    const int begin = chunk * kChunk, end = std::min(n, begin + kChunk);
    const std::vector<Eigen::Vector2d> chunk_from(from.begin() + begin, from.begin() + end);
    std::vector<Eigen::Vector2d> chunk_to(to.begin() + begin, to.begin() + end);
    const std::vector<char> chunk_refined = refine_tracks_affine(
        keyframe_.image, f.gray.mat(), chunk_from, &chunk_to, options_.stereo_track_refinement);
    std::copy(chunk_to.begin(), chunk_to.end(), to.begin() + begin);
    std::copy(chunk_refined.begin(), chunk_refined.end(), refined.begin() + begin);
  });
  // A track that cannot be refined is left out: on the corridor those lag by 0.57 px on
  // average, mostly windows at the image's border and lost tracks.
  const CameraModel& camera = f.input.camera;
  std::vector<char> keep(observations.size(), 1);
  for (size_t j = 0; j < near.size(); ++j) {
    keep[near[j]] = refined[j];
    if (refined[j])
      observations[near[j]].x_cur =
          camera.pinhole.normalize(camera.has_distortion() ? camera.undistort(to[j]) : to[j]);
  }
  std::vector<StereoScaleObservation> kept;
  std::vector<int64_t> kept_ids;
  for (size_t k = 0; k < observations.size(); ++k) {
    if (!keep[k]) continue;
    kept.push_back(observations[k]);
    kept_ids.push_back(ids[k]);
  }
  *observed = std::move(kept_ids);
  return kept;
}

void VisualOdometry::add_current_disparities(Frame& f) const {
  if (!options_.stereo_current_disparity) return;
  const double fx_baseline = f.input.camera.pinhole.fx * f.input.baseline_m;
  for (size_t k = 0; k < f.observed.size() && k < f.scale_observations.size(); ++k) {
    const auto now = f.points3d.find(f.observed[k]);
    if (now != f.points3d.end()) f.scale_observations[k].disparity_cur = fx_baseline / now->second.z();
  }
}

void VisualOdometry::measure_stereo_motion(Frame& f) {
  if (!f.stereo) return;
  add_current_disparities(f);
  const auto start = std::chrono::steady_clock::now();
  RelativePoseEstimate& est = f.result.estimate.estimate;
  const StereoRig rig{f.input.camera.pinhole.fx, f.input.camera.pinhole.fy, f.input.baseline_m};
  StereoScaleOptions options = options_.stereo_scale;
  options.disparity_offset_px = f.result.disparity_offset_px = offset_filter_.offset();
  f.stereo_motion = estimate_stereo_motion(est.pose.R, rig, f.scale_observations, options,
                                           pair_options().covariance.independent_points);
  if (f.stereo_motion.ok) {
    est.pose.R = f.stereo_motion.R;
    est.covariance.topLeftCorner<3, 3>() = f.stereo_motion.covariance.topLeftCorner<3, 3>();
  }
  f.result.stages.scale_ms += ms_since(start);
}

void VisualOdometry::fit_translation_without_baseline(Frame& f) {
  // No baseline: the translation is zero, within a pair's length per axis (mono_scale), unless
  // the keyframe's stereo points measured it (at rest: zero within their noise; a camera turning
  // about a point behind it: the lever arm's arc).
  VisualOdometryResult& r = f.result;
  const RelativePoseEstimate& est = r.estimate.estimate;
  r.motion = RelativePose(f.oriented.pose.R, Eigen::Vector3d::Zero());
  r.motion_covariance.setZero();
  r.motion_covariance.topLeftCorner<3, 3>() = est.covariance.topLeftCorner<3, 3>();
  r.motion_covariance.bottomRightCorner<3, 3>() =
      options_.mono_scale * options_.mono_scale * Eigen::Matrix3d::Identity();
  r.motion_covariance_valid = est.covariance_valid;
  if (f.stereo) {
    r.stereo_scale_attempted = true;
    r.scale_observations = std::move(f.scale_observations);
    const StereoMotionEstimate& m = f.stereo_motion;
    r.stereo_scale.near_points = m.points;
    r.stereo_scale.inliers = m.inliers;
    r.stereo_scale.status = m.ok ? StereoScaleStatus::kOk : StereoScaleStatus::kTooFewNearPoints;
    if (m.ok) {
      r.motion.t = m.t;
      r.motion_covariance = m.covariance;
      r.stereo_scale.scale = m.t.norm();
      r.stereo_scale.sigma = std::sqrt(std::max(0.0, m.covariance.bottomRightCorner<3, 3>().trace()));
      r.scale_known = true;
    }
  } else if (options_.mono_relative_scale) {
    measure_mono_translation(f);  // from the keyframe's depths, where it knows them
  }
  r.motion_covariance.topLeftCorner<3, 3>() += f.oriented.motion_rotation_extra;
}

void VisualOdometry::fit_scale(Frame& f) {
  // The keyframe's stereo points seen again, with this frame's disparities, fitted in disparity
  // and image space (estimate_stereo_scale); without a usable fit, the configured length and
  // scale_known false.
  if (f.rotation_only || !f.baseline) return fit_translation_without_baseline(f);
  VisualOdometryResult& r = f.result;
  r.baseline = true;
  const RelativePoseEstimate& est = r.estimate.estimate;
  const RelativePose& pose = f.oriented.pose;
  r.motion = pose;
  // Without the estimator's covariance the rotation gets a blank wall's (VoOrientation::orient)
  // and the translation's direction a radian: what its data could not fix.
  Eigen::Matrix<double, 6, 6> unknown = Eigen::Matrix<double, 6, 6>::Zero();
  const Eigen::Vector3d u = pose.t.normalized();
  if (all_finite(u))
    unknown.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() - u * u.transpose();
  // A blank wall's translation is as unknown as its rotation is uncertain: its points are sensor
  // noise on a plane (the plain corridors' corners: 50-100 degrees off where the curvature
  // claimed a few).
  f.unit_covariance = est.covariance_valid ? est.covariance : unknown;
  if (f.oriented.estimate.blank_wall)
    f.unit_covariance.bottomRightCorner<3, 3>() += unknown.bottomRightCorner<3, 3>();
  double scale = options_.mono_scale, scale_sigma = 0.0;
  if (f.stereo) {
    add_current_disparities(f);
    r.stereo_scale_attempted = true;
    const auto scale_start = std::chrono::steady_clock::now();
    r.scale_observations = std::move(f.scale_observations);
    const StereoRig rig{f.input.camera.pinhole.fx, f.input.camera.pinhole.fy, f.input.baseline_m};
    // The pair's own pose: its rotation and translation explain its points together, and the
    // scale is fitted to those points (with the anchored rotation the demo's ATE was 0.0135 m
    // against 0.0115); a pose the map overruled is replaced by the one fitted under the map's.
    const RelativePose& scale_pose = f.oriented.scale_pose;
    offset_filter_.update(scale_pose, rig, r.scale_observations, options_.stereo_scale);
    StereoScaleOptions scale_options = options_.stereo_scale;
    scale_options.disparity_offset_px = r.disparity_offset_px = offset_filter_.offset();
    r.stereo_scale = estimate_stereo_scale(scale_pose, rig, r.scale_observations, scale_options);
    if (r.stereo_scale.status == StereoScaleStatus::kOk) {
      scale = r.stereo_scale.scale;
      // The scale's points share their errors as the direction's do: they count as at most the
      // translation's independent points (the rendered corridor's scale was 3-5 of its fitted
      // sigmas off).
      scale_sigma = r.stereo_scale.sigma *
                    std::sqrt(std::max(1.0, r.stereo_scale.near_points /
                                                pair_options().covariance.independent_translation_points));
      r.scale_known = true;
    }
    r.stages.scale_ms += ms_since(scale_start);
  } else if (options_.mono_relative_scale && !fit_mono_scale(f, &scale, &scale_sigma)) {
    scale = mono_length_without_depths(f, &scale_sigma);
  }
  set_length(f, scale, scale_sigma);
  if (f.stereo) prefer_stereo_translation(f);
}

void VisualOdometry::set_length(Frame& f, double scale, double sigma) {
  VisualOdometryResult& r = f.result;
  const RelativePose& pose = f.oriented.pose;
  r.motion.t = pose.t * scale;
  r.motion_covariance = metric_motion_covariance(f.unit_covariance, pose.t, scale, sigma);
  r.motion_covariance.topLeftCorner<3, 3>() += f.oriented.motion_rotation_extra;
  r.motion_covariance_valid = true;
  f.length = scale;
  f.length_sigma = sigma;
}

void VisualOdometry::prefer_stereo_translation(Frame& f) {
  if (!(options_.stereo_translation_margin > 0.0)) return;
  VisualOdometryResult& r = f.result;
  const auto start = std::chrono::steady_clock::now();
  const StereoRig rig{f.input.camera.pinhole.fx, f.input.camera.pinhole.fy, f.input.baseline_m};
  StereoScaleOptions options = options_.stereo_scale;
  options.disparity_offset_px = r.disparity_offset_px;
  // Its points share their errors as the direction's do: as many independent ones. The rotation
  // is refined with it (held, the translation takes in the rotation's error) but stays the pair's.
  const StereoMotionEstimate m =
      estimate_stereo_motion(r.motion.R, rig, r.scale_observations, options,
                             pair_options().covariance.independent_translation_points);
  r.stages.scale_ms += ms_since(start);
  const Eigen::Matrix3d C = m.covariance.bottomRightCorner<3, 3>();
  if (!m.ok || !all_finite(m.t) || !all_finite(C) ||
      !(options_.stereo_translation_margin * C.trace() <
        r.motion_covariance.bottomRightCorner<3, 3>().trace()))
    return;
  r.motion.t = m.t;
  r.motion_covariance.bottomRightCorner<3, 3>() = C;
  r.motion_covariance.topRightCorner<3, 3>().setZero();
  r.motion_covariance.bottomLeftCorner<3, 3>().setZero();
  r.scale_known = true;
}

}  // namespace hybrid_vo
