// VisualOdometry's keyframe policy: every frame is paired with the last keyframe. A frame becomes
// the keyframe when its parallax after the rotation reaches keyframe_parallax_px (a baseline
// that fixes the translation), when the keyframe's points are leaving the view (keyframe_overlap,
// keyframe_min_points), when it has turned keyframe_max_turn_deg from it, and when a new chain
// starts at it (the first frame, or too few matches to
// pair it). Until then the keyframe stays, so that the baseline grows: frames with some parallax
// are answered with their full pose against it, those that moved too little off their rotation
// for a baseline (min_parallax_px), or whose points' noise explains what the rotation leaves
// (model selection), with their rotation alone; in mono, those with the keyframe before where it
// gives them a baseline (previous_keyframe_parallax_px). Without rotation-only pairs such frames
// are left out, as any frame whose pose is not found. Also what a keyframe keeps.
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "vo_frame.h"

namespace hybrid_vo {

bool VisualOdometry::low_parallax(const Frame& f) const {
  return f.parallax >= 0.0 && f.parallax < options_.min_parallax_px;
}

VisualOdometry::Pairing VisualOdometry::decide_keyframe(Frame& f) {
  VisualOdometryResult& r = f.result;
  if (!keyframe_.valid) {
    r.status = f.was_reset ? VoStatus::kReset : VoStatus::kFirstFrame;
    r.message = f.was_reset ? "time went backwards: odometry reset" : "keyframe initialised";
    r.reference_stamp = f.input.stamp;
    return Pairing::kNewKeyframe;
  }
  r.reference_stamp = keyframe_.stamp;
  if (r.num_point_matches < options_.min_point_matches &&
      r.num_line_matches < options_.min_line_matches) {
    r.status = VoStatus::kTooFewFeatures;
    r.message = "too few matches (" + std::to_string(r.num_point_matches) + " points, " +
                std::to_string(r.num_line_matches) + " segments): re-initialised";
    return Pairing::kNewKeyframe;
  }
  if (keyframe_.paired_points < 0) keyframe_.paired_points = r.num_point_matches;
  if (low_parallax(f)) {
    r.status = VoStatus::kLowParallax;
    r.message = "parallax after the rotation " + std::to_string(f.parallax) + " px";
    if (!options_.rotation_only_pairs) return Pairing::kSkip;
    return Pairing::kEstimateKeepKeyframe;
  }
  return Pairing::kEstimate;
}

bool VisualOdometry::keeps_keyframe(const Frame& f) const {
  const bool short_baseline = f.rotation_only || !f.baseline ||
                              (f.parallax >= 0.0 && f.parallax < options_.keyframe_parallax_px);
  const int seen = f.result.num_point_matches;
  const double turned_deg = Eigen::AngleAxisd(f.result.motion.R).angle() * 180.0 / M_PI;
  if (options_.keyframe_max_turn_deg > 0.0 && turned_deg > options_.keyframe_max_turn_deg)
    return false;
  return short_baseline && seen >= options_.keyframe_min_points &&
         seen >= options_.keyframe_overlap * std::max(0, keyframe_.paired_points);
}

bool VisualOdometry::estimate_against_previous_keyframe(Frame& f, Pairing pairing) {
  const bool short_parallax =
      pairing == Pairing::kEstimateKeepKeyframe ||
      (pairing == Pairing::kEstimate && f.parallax >= 0.0 &&
       f.parallax < options_.previous_keyframe_parallax_px);
  if (!short_parallax || !previous_keyframe_.valid || f.stereo || !keeps_keyframe(f))
    return false;
  // What the frame knows of its pair with the keyframe, should the one before give none.
  VisualOdometryResult kept = f.result;
  const std::vector<int64_t> kept_ids = f.point_ids;
  const double kept_parallax = f.parallax;
  const RotationOnlyEstimate kept_rotation = f.rotation;
  std::swap(keyframe_, previous_keyframe_);
  VisualOdometryResult& r = f.result;
  r.matches = TwoViewMatches();
  f.point_ids.clear();
  f.parallax = -1.0;
  f.rotation = RotationOnlyEstimate();
  match_points(f);
  match_segments(f);
  const bool enough = r.num_point_matches >= options_.min_point_matches ||
                      r.num_line_matches >= options_.min_line_matches;
  if (enough && f.parallax > kept_parallax && !low_parallax(f)) {
    r.reference_stamp = keyframe_.stamp;
    prepare_pair(f);
    f.baseline = true;
    // A pair the model selection takes for a rotation alone is no baseline either.
    r.paired_with_keyframe_before = estimate(f) && !f.rotation_only;
    if (r.paired_with_keyframe_before) return true;
  }
  std::swap(keyframe_, previous_keyframe_);
  f.result = std::move(kept);
  f.point_ids = kept_ids;
  f.parallax = kept_parallax;
  f.rotation = kept_rotation;
  f.rotation_only = false;
  f.vps_detected = false;
  return false;
}

VisualOdometryResult VisualOdometry::keep_as_keyframe(Frame& f) {
  finish_stereo(f);
  finish_redetection(f);
  // The features that keyframe a frame: all the tracker holds once it has re-detected; in stereo
  // the new ones are pending.
  std::vector<int64_t> pending;
  if (f.tracking && f.stereo)
    for (const int64_t id : klt_.ids())
      if (!f.points.count(id)) pending.push_back(id);
  make_keyframe(f, f.tracking ? klt_points() : std::move(f.points), std::move(pending));
  VisualOdometryResult& r = f.result;
  r.total_ms = ms_since(f.start);
  if (r.status == VoStatus::kFirstFrame || r.status == VoStatus::kReset) r.frontend_ms = r.total_ms;
  return std::move(r);
}

VisualOdometryResult VisualOdometry::skip_frame(Frame& f) {
  // Its stereo matching is left undone.
  f.stereo_loop.cancel();
  finish_redetection(f);
  f.result.total_ms = ms_since(f.start);
  return std::move(f.result);
}

void VisualOdometry::make_keyframe(Frame& f, std::map<int64_t, Eigen::Vector2d> points,
                                   std::vector<int64_t> pending) {
  const VisualOdometryInput& input = f.input;
  std::map<int64_t, InverseDepth> depths = keyframe_depths(f);
  // The one before stays for the frames that see too little of this one's baseline, where the
  // two are a baseline apart: this one was made by a pair whose direction is known (as for a
  // first keyframe's depths). A turning camera's keyframes are not: its pairs with the one before
  // would span its turn too (TUM rpy: 0.96 -> 1.62 degrees per pair, 4.05 -> 4.26 over 1 s).
  const VisualOdometryResult& r = f.result;
  const double sure = kLooseDirectionFactor * options_.mono_depth_max_direction_sigma;
  const bool translated = r.became_keyframe && r.baseline && !f.rotation_only &&
                          r.motion_covariance_valid && translation_direction_sigma(r) <= sure;
  if (translated && !f.stereo && options_.previous_keyframe_parallax_px > 0.0)
    previous_keyframe_ = std::move(keyframe_);
  else
    previous_keyframe_ = Keyframe();
  keyframe_ = Keyframe();
  keyframe_.made_depths = depths;
  keyframe_.depths = std::move(depths);
  keyframe_.valid = true;
  keyframe_.stamp = input.stamp;
  keyframe_.points = std::move(points);
  keyframe_.points3d = std::move(f.points3d);
  keyframe_.stereo = std::move(f.pair);
  keyframe_.stereo_pending = std::move(pending);
  for (size_t i = 0; i < f.line_ids.size() && i < f.features.lines.segments.size(); ++i)
    keyframe_.tracked_lines[f.line_ids[i]] = f.features.lines.segments[i];
  keyframe_.features = std::move(f.features);
  keyframe_.camera = input.camera;
  // A copy: the caller may reuse its image buffer for the next frame.
  if (options_.stereo_refine_tracks && !input.right_image.empty())
    keyframe_.image = f.gray.mat().clone();
  keyframe_.R_wc = orientation_.R_wc();
  keyframe_.R_wc_covariance = orientation_.covariance();
  keyframe_.centre = centre_;
  keyframe_.pose_covariance = pose_covariance_.scaled_covariance();
  keyframe_.paired_points = -1;
  last_answer_stamp_ = input.stamp;
  last_answer_R_wc_ = keyframe_.R_wc;
  if (input.external.has_lines)
    for (size_t i = 0; i < input.external.lines.size() && i < input.external.line_ids.size(); ++i)
      keyframe_.external_lines[input.external.line_ids[i]] = input.external.lines[i];
  keyframe_.points_undistorted = input.external.has_points && input.external.points_undistorted;
  keyframe_.lines_undistorted = input.external.has_lines && input.external.lines_undistorted;
  remember_window_keyframe(f);
}

}  // namespace hybrid_vo
