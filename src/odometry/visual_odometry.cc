// VisualOdometry: a frame's schedule (run_frame), its input and its pose. The stages live by job
// in vo_tracking.cc (points and segments), vo_keyframe_policy.cc, vo_estimation.cc,
// vo_orientation.cc (VoOrientation) and vo_stereo_scale.cc; a frame's state in vo_frame.h.
#include "hybrid_vo/odometry/visual_odometry.h"

#include <cmath>

#include "hybrid_vo/geometry/rotation.h"
#include "vo_frame.h"

namespace hybrid_vo {

VisualOdometryOptions::VisualOdometryOptions() {
  features.points = video_point_matching_options();
  features.lines = video_line_matching_options();
  // Low texture (issue 30, doc/low_texture.md): a VP may rest on three long segments, and
  // segments that stop short of a corner still meet.
  estimator.vp_detection.min_long_inliers = 3;
  estimator.vp_detection.min_support_px = 150.0;
  estimator.junctions.length_fraction = 0.15;
}

const char* to_string(VoStatus status) {
  switch (status) {
    case VoStatus::kFirstFrame:
      return "first frame";
    case VoStatus::kOk:
      return "ok";
    case VoStatus::kLowParallax:
      return "low parallax";
    case VoStatus::kRotationOnly:
      return "rotation only";
    case VoStatus::kTooFewFeatures:
      return "too few features";
    case VoStatus::kNoPose:
      return "no pose";
    case VoStatus::kInvalidInput:
      return "invalid input";
    case VoStatus::kReset:
      return "reset";
  }
  return "unknown";
}

VisualOdometry::VisualOdometry(const VisualOdometryOptions& options)
    : options_(options),
      worker_(std::make_unique<WorkerThread>(options.concurrent)),
      klt_(options.klt, options.features.points.max_features),
      line_tracker_(options.line_tracking, options.features.lines),
      line_flow_(options.line_flow_tracking),
      orientation_(options),
      offset_filter_(options.stereo_offset),
      budget_(options.budget) {
  apply_work_level(budget_.level());
}

VisualOdometry::~VisualOdometry() = default;

void VisualOdometry::reset() {
  restart();
  orientation_.reset();
  centre_.setZero();
  pose_covariance_.reset();
  last_stamp_ = -1e300;
}

void VisualOdometry::restart() {
  orientation_.restart();
  klt_.reset();
  line_tracker_.reset();
  line_flow_.reset();
  keyframe_ = Keyframe();
  previous_keyframe_ = Keyframe();
  last_answer_stamp_ = -1e300;
  mono_speed_ = -1.0;
  window_.clear();
}

VisualOdometryResult VisualOdometry::process(const VisualOdometryInput& input) {
  const double caller_cpu_start = thread_cpu_ms(), worker_cpu_start = worker_->cpu_ms();
  VisualOdometryResult r = run_frame(input);
  // Each thread's CPU time for this frame: every job of the frame is done by now.
  r.stages.caller_cpu_ms = thread_cpu_ms() - caller_cpu_start;
  r.stages.worker_cpu_ms = worker_->cpu_ms() - worker_cpu_start;
  r.work_level = budget_.level();
  const int next = budget_.update(r.stages.caller_cpu_ms + r.stages.worker_cpu_ms);
  r.average_cpu_ms = budget_.average_cpu_ms();
  if (next != r.work_level) apply_work_level(next);
  return r;
}

VisualOdometryResult VisualOdometry::run_frame(const VisualOdometryInput& input) {
  Frame f(input);
  if (!begin_frame(f)) return std::move(f.result);
  // The second thread's queue, in order: the stereo pair's pyramids, the segments, then its share
  // of the KLT searches, of the stereo searches, of the re-detection and of the scale's
  // refinement. This thread tracks the points meanwhile, then estimates while the second one
  // matches the stereo points, and takes what is left of a shared stage when it needs its results.
  if (f.stereo) {
    if (f.klt_pyramid) f.flat_field_gain = klt_.flat_field_gain();  // before tracking updates it
    f.pyramids_job = worker_->submit([this, &f] { build_stereo_pyramids(f); });
  }
  build_pyramid(f);                        // before the segments, which may follow its flow
  const bool lines = options_.use_lines && !input.external.has_lines;
  const bool flow = lines && options_.track_lines && options_.line_flow;
  if (flow) start_segment_detection(f);
  else if (lines) f.segments_job = worker_->submit([this, &f] { track_segments(f); });
  track_points(f);                         // both threads (the KLT searches)
  if (flow) follow_segments(f);            // both threads
  match_points(f);                         // this thread, as everything not marked
  // Both threads; a skipped frame needs none, a rotation-only one its translation in stereo.
  if (!low_parallax(f) || options_.rotation_only_pairs) start_stereo(f);
  start_redetection(f);                    // both threads; only the next frame needs it
  f.segments_job.get();
  if (keyframe_.valid) match_segments(f);
  const Pairing pairing = decide_keyframe(f);
  if (pairing == Pairing::kNewKeyframe) return keep_as_keyframe(f);
  if (pairing == Pairing::kSkip) return skip_frame(f);
  if (!estimate_against_previous_keyframe(f, pairing)) {
    prepare_pair(f);
    f.baseline = pairing == Pairing::kEstimate;
    if (!estimate(f)) {
      if (f.baseline) return skip_frame(f);
      f.rotation_only = true;  // without a baseline, the rotation may still be found
    }
  }
  if (f.rotation_only && !estimate_rotation(f)) return skip_frame(f);
  observe_scale(f);                        // both threads (the refinement)
  finish_stereo(f);                        // both threads
  if (f.rotation_only || !f.baseline) measure_stereo_motion(f);
  orient(f);
  fit_scale(f);
  // Paired with the keyframe before, which is keyframe_ until the frame is answered.
  if (f.result.paired_with_keyframe_before || keeps_keyframe(f)) {
    refine_keyframe_depths(f);
    return answer_without_keyframe(f);
  }
  fit_window_scale(f);
  integrate(f);
  return keep_as_keyframe(f);
}

bool VisualOdometry::begin_frame(Frame& f) {
  const VisualOdometryInput& input = f.input;
  VisualOdometryResult& r = f.result;
  const auto report_pose = [&] {
    r.R_wc = orientation_.R_wc();
    r.centre = centre_;
    r.pose_covariance = pose_covariance_.covariance();
    r.pose_covariance_gaps = pose_covariance_.gaps();
  };
  report_pose();
  if (input.image.empty() || !input.camera.valid() || !std::isfinite(input.stamp)) {
    r.status = VoStatus::kInvalidInput;
    r.message = input.image.empty() ? "empty image" : "invalid camera or stamp";
    return false;
  }
  if (input.stamp < last_stamp_) {
    reset();
    f.was_reset = true;
    report_pose();  // the origin again
  }
  // The segments move as the camera turns at its last rate; beyond that, by their own motion.
  if (keyframe_.valid && input.stamp > last_stamp_)
    f.segment_motion = orientation_.segment_motion(input.camera.pinhole, input.stamp - last_stamp_);
  last_stamp_ = input.stamp;
  f.gray = GrayImage(input.image);
  f.tracking = !input.external.has_points && options_.point_source == PointFeatureSource::kTracking;
  f.stereo = !input.right_image.empty() && input.baseline_m > 0.0;
  // The KLT tracker's pyramid of this image serves the stereo matching when its window and
  // levels suffice.
  f.klt_pyramid = f.tracking && options_.klt.window_px >= options_.stereo.window_px &&
                  options_.klt.pyramid_levels >= options_.stereo.pyramid_levels;
  if (f.stereo) {
    f.pair.camera = input.camera.pinhole;
    f.pair.baseline_m = input.baseline_m;
  }
  return true;
}

void VisualOdometry::orient(Frame& f) {
  VoOrientation::Pair pair;
  pair.estimate = &f.result.estimate.estimate;
  pair.matches = &f.result.matches;
  pair.keyframe_camera = keyframe_.camera.pinhole;
  pair.camera = f.input.camera.pinhole;
  pair.dt = f.input.stamp - keyframe_.stamp;
  pair.vps_detected = f.vps_detected;
  pair.independent_rotation = f.rotation_only || f.stereo_motion.ok;
  f.oriented = orientation_.orient(keyframe_.R_wc, keyframe_.R_wc_covariance, pair);
  f.result.orientation = f.oriented.estimate;
}

void VisualOdometry::integrate(Frame& f) {
  VisualOdometryResult& r = f.result;
  orientation_.advance(f.oriented, f.input.stamp - keyframe_.stamp,
                       r.motion_covariance.topLeftCorner<3, 3>());
  // The current camera's centre in the keyframe is -R^T t.
  centre_ = keyframe_.centre - keyframe_.R_wc * r.motion.R.transpose() * r.motion.t;
  r.R_wc = orientation_.R_wc();
  r.centre = centre_;
  // A mono keyframe made by a pair with a baseline triangulates its depths with that pair's
  // length: its error is the unit's from now on.
  pose_covariance_.integrate(keyframe_.pose_covariance, r.R_wc, r.motion.t,
                             r.motion_covariance_valid ? &r.motion_covariance : nullptr,
                             orientation_.reported_covariance(), !f.stereo && r.baseline);
  // Its length's error is in the integration (along t); its direction's stretches the depths.
  if (!f.stereo && r.baseline) pose_covariance_.add_unit_variance(f.direction_variance());
  r.pose_covariance = pose_covariance_.covariance();
  r.pose_covariance_gaps = pose_covariance_.gaps();
  r.became_keyframe = true;
  const double dt = f.input.stamp - keyframe_.stamp;
  if (!f.stereo && r.baseline && dt > 0.0) mono_speed_ = r.motion.t.norm() / dt;
  if (f.rotation_only) return;
  r.status = VoStatus::kOk;
  if (r.message.empty()) r.message = "ok";
}

VisualOdometryResult VisualOdometry::answer_without_keyframe(Frame& f) {
  VisualOdometryResult& r = f.result;
  const Eigen::Matrix3d motion_rotation = r.motion_covariance.topLeftCorner<3, 3>();
  r.R_wc = f.oriented.R_wc;
  r.centre = keyframe_.centre - keyframe_.R_wc * r.motion.R.transpose() * r.motion.t;
  // As integrate() would report them, without taking the pair on.
  const Eigen::Matrix3d orientation = orientation_.reported_covariance(f.oriented, motion_rotation);
  Matrix7d scaled = keyframe_.pose_covariance;
  if (!(r.motion_covariance_valid &&
        propagate_scaled_pose_covariance(keyframe_.pose_covariance, r.R_wc, r.motion.t,
                                         r.motion_covariance, orientation, false, &scaled)))
    scaled.block<3, 3>(3, 3) = orientation;
  r.pose_covariance = scaled.topLeftCorner<6, 6>();
  r.pose_covariance_gaps = pose_covariance_.gaps();
  // The rate since the last answered frame, for the segments' motion in the next one: from a
  // rotation alone, which is exact to hundredths of a degree; a full pair's without a baseline
  // is off by tenths (a rate of degrees a second at 30 Hz, which on the white panels of TUM
  // misled the segments' tracking enough to end 14 degrees off instead of 4.5).
  const double dt = f.input.stamp - last_answer_stamp_;
  if ((f.rotation_only || r.paired_with_keyframe_before) && dt > 0.0 && dt < 1.0)
    orientation_.set_rate(nearest_rotation(r.R_wc.transpose() * last_answer_R_wc_), dt);
  last_answer_stamp_ = f.input.stamp;
  last_answer_R_wc_ = r.R_wc;
  if (r.paired_with_keyframe_before) {
    r.status = VoStatus::kOk;
    r.message += "; paired with the keyframe before";
    std::swap(keyframe_, previous_keyframe_);
  } else if (!f.rotation_only) {
    r.status = VoStatus::kOk;
    r.message += "; no baseline: the keyframe stays";
  }
  f.stereo_loop.cancel();
  finish_redetection(f);
  r.total_ms = ms_since(f.start);
  return std::move(r);
}

}  // namespace hybrid_vo
