#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hybrid_vo/estimation/rotation_only.h"
#include "hybrid_vo/estimation/stereo_scale.h"
#include "hybrid_vo/estimation/two_view_depth.h"
#include "hybrid_vo/features/affine_tracking.h"
#include "hybrid_vo/features/frontend.h"
#include "hybrid_vo/features/klt_tracker.h"
#include "hybrid_vo/features/line_flow_tracker.h"
#include "hybrid_vo/features/line_tracker.h"
#include "hybrid_vo/features/stereo.h"
#include "hybrid_vo/features/worker_thread.h"
#include "hybrid_vo/geometry/pose_covariance.h"
#include "hybrid_vo/lines/two_view.h"
#include "hybrid_vo/odometry/cpu_budget.h"
#include "hybrid_vo/odometry/stage_timings.h"
#include "hybrid_vo/odometry/vo_orientation.h"

namespace hybrid_vo {

enum class PointFeatureSource {
  kTracking,     // KLT tracks across video frames (default)
  kDescriptors,  // SIFT/ORB matched against the keyframe
};

struct VisualOdometryOptions {
  VisualOdometryOptions();  // the video presets of the front end (ORB, FLD) and of low texture

  PointFeatureSource point_source = PointFeatureSource::kTracking;
  bool use_lines = true;
  // Descriptors for points (kDescriptors) and segments. features.points.max_features is the one
  // cap on the points per frame, whatever their source (the KLT tracker takes it too).
  FrontendOptions features;
  KltTrackerOptions klt;
  // Segments tracked frame to frame by their own geometry (LineTracker) and paired with the
  // keyframe's by track id; false: the keyframe's segments matched by LBD in every frame.
  bool track_lines = true;
  LineTrackerOptions line_tracking;
  // With track_lines: the segments followed from frame to frame by their flow and detected only
  // where their tracks thin out (LineFlowTracker, issue 57); false: detected and described in
  // every frame and tracked by their geometry (LineTracker).
  bool line_flow = false;
  LineFlowTrackerOptions line_flow_tracking;
  // The segments and the stereo matching on a second thread, beside the points and the
  // estimator. The results do not depend on it.
  bool concurrent = true;
  TwoViewOptions estimator;   // preset "hybrid", VPs detected jointly from the segments
  // Frames whose points move less than this off the rotation that best explains them (median
  // transfer error to the keyframe, the parallax after the rotation: a pan is no baseline, and a
  // slow one is not standing still) are no baseline. With rotation_only_pairs they are answered
  // all the same (else left out).
  double min_parallax_px = 2.0;
  // The keyframe is replaced once a frame's parallax after the rotation reaches
  // keyframe_parallax_px (a baseline that fixes the translation's direction: at 30 Hz a pair of
  // consecutive frames has 2-3 px, and its direction was 3-6 degrees off), or once fewer than
  // keyframe_overlap of the point matches of its first pair, or fewer than keyframe_min_points,
  // remain to measure it. Frames before that are estimated against it and answered, each with
  // the baseline it has (or its rotation alone), so that the parallax builds up.
  double keyframe_parallax_px = 7.0;
  // Mono: a frame with less parallax than this to a keyframe that stays (the frames just after
  // it replaced the one before) is paired with the keyframe before instead where that one gives
  // it more, and a baseline (issue 58: a fifth to a half of the hand-held rooms' pairs had none,
  // and those with 2-3 px were 10-25 degrees off in direction). It is answered against that
  // keyframe and becomes no keyframe itself. Frames below min_parallax_px try it whatever this
  // is above 0; 0: never.
  double previous_keyframe_parallax_px = 3.0;
  double keyframe_overlap = 0.3;
  int keyframe_min_points = 30;
  // ... or once a frame has turned more than this from the keyframe (degrees; 0: no limit). A
  // keyframe's link to the next carries the orientation on; a fast-turning hand-held camera keeps
  // its keyframe over tens of degrees (TUM fr1/rpy: up to 77) whose links were 1.8 degrees off
  // (median). 15 takes TUM rpy's 1 s windows from 4.05 to 2.94 degrees and changes no other real
  // set, but costs the rendered hand-held room 1 (AUC@10 82.6 -> 71.6), a keyframe made with 3 px
  // of parallax (doc/real_data.md): off by default.
  double keyframe_max_turn_deg = 0.0;
  // Rotation-only pairs: where the points' own noise explains what the rotation leaves of their
  // motion (model_selection, motion_model_selection.h), the frame's rotation against the keyframe
  // is published with an honest covariance; else the full motion's. Without a baseline (or with
  // a rotation alone) the translation is not the epipolar geometry's: zero in mono, within
  // mono_scale (only a baseline moves a mono position: a pan's tracks drift enough for the full
  // model to win now and then, and its direction is noise); in stereo the keyframe's stereo
  // points give the rotation and the metric translation together.
  bool rotation_only_pairs = true;
  bool model_selection = true;
  RotationOnlyOptions rotation_only;
  int min_point_matches = 8;  // below this and without enough segments the pair is hopeless
  int min_line_matches = 12;
  // Mono: the first pair's translation has this length; later pairs take the length that
  // agrees with their keyframe's points as triangulated before (relative scale), those whose
  // inverse depth is known to within mono_depth_max_sigma of itself; where none are, the last
  // pair's speed (before any, a length that goes with the parallax). Every pair with a baseline
  // refines its keyframe's depths. Without a baseline
  // the translation is measured from the keyframe's depths where it knows them, else zero within
  // mono_scale.
  double mono_scale = 1.0;
  bool mono_relative_scale = true;
  double mono_depth_max_sigma = 0.3;
  // A length (or a translation without a baseline) from the keyframe's depths needs this many
  // points that agree (and most of those it has).
  int mono_min_depth_points = 10;
  // Mono: the length of the link a frame adds as it becomes the keyframe is fitted together with
  // the last links and the points tracked across them (estimation/window_scale.h), over this many
  // keyframes, the new one included; below 3 each link keeps its pair's own length. Longer
  // windows did worse with the pairs' rotations and directions held (KITTI 01 mono, seed 0: drift
  // 1.37 % over 3 keyframes, 1.62 over 5, 2.50 over 8, 2.84 over 12; 2.56 without): a track over
  // many links sees their composed errors.
  int mono_window_keyframes = 3;
  // A pair triangulates its points only when its translation's direction is this sure
  // (radians; a blank wall's is not).
  double mono_depth_max_direction_sigma = 0.05;
  StereoOptions stereo;
  StereoScaleOptions stereo_scale;  // the metric scale from the keyframe's stereo points
  DisparityOffsetOptions stereo_offset;  // self-calibration of a constant disparity offset
  bool stereo_current_disparity = true;  // fit the current frame's disparities too
  // The scale's current points re-tracked from the keyframe with an affine window (KLT tracking
  // only): the tracker's translated window lags along the flow on surfaces that come closer,
  // which shortens the scale (affine_tracking.h). The pose keeps the tracker's points.
  bool stereo_refine_tracks = true;
  AffineTrackingOptions stereo_track_refinement;
  // The map of world directions (direction_map/direction_map.h): the pairs' VPs kept as landmarks in the
  // odometry frame, priors for the next pair's VPs, and (anchor_orientation) the absolute
  // reference that corrects each frame's orientation, predicted by the pair's rotation, wherever
  // the camera sees its directions; found again by their structure after a blank wall. Each
  // pair's rotation covariance grows the orientation's uncertainty (plus rotation_drift_floor_deg
  // per axis): it tells a pair whose points barely separate rotation from translation (white
  // panels seen from 2 m: 0.08 deg) from a well conditioned one (KITTI: 0.003 deg), where VPs,
  // with their tenths of a degree of noise, must not move it.
  bool use_direction_map = true;
  bool anchor_orientation = true;
  OrientationFilterOptions orientation;
  // How far every estimated rotation may be off as a whole, in its angle and in its axis (a
  // fraction: a focal length, a camera's mounting, or a ground truth's own): the orientation's
  // reported uncertainty grows by it times the angle turned, per axis
  // (VoOrientation::reported_covariance). 0: the camera_info is taken as exact (a pan in place
  // over a photograph, whose pairs are 0.001 degrees off, would otherwise claim ten times that
  // per degree turned). A full pair's own share of its angle is the estimator's
  // (PairCovarianceOptions::turn_fraction): KITTI's truth turns 0.7 % more than every two-view
  // estimate (hybrid_vo_bench_frontend --direct-gap), which that covers.
  double rotation_calibration_sigma = 0.0;
  // A share of the angle turned, per axis, that a full pair's rotation may be off beyond what the
  // pair itself reports: on the rendered corridors (exact calibration) pairs turning more than 3
  // degrees in a corner were off by about 1 % of their angle, four times what they claimed
  // (rotation NEES 15.7), while straight ones were honest: the translation, held poorly while
  // turning, takes some of the rotation with it. A rotation-only pair has no translation to
  // trade (a pan over a photograph: 0.08 % of its angle).
  double full_pair_turn_fraction = 0.01;
  // Stereo: a pair with a baseline takes its translation from the keyframe's stereo points seen
  // again (estimate_stereo_motion) where its covariance's trace is at most 1/margin of the
  // epipolar direction times the scale's: at a few pixels of parallax the direction is poor and
  // the points' depths are not (rendered rooms at 30 Hz: AUC@10 60 -> 78), while far points
  // (KITTI) leave the epipolar one. The margin keeps it there where the two are alike (at 1 it
  // took 14 of KITTI's 50 pairs and its ATE grew by half). 0: never.
  double stereo_translation_margin = 2.0;
  // A CPU budget per frame (both threads): the front end drops its least useful work, level by
  // level (cpu_budget.h), while the recent frames exceed it. Off by default.
  CpuBudgetOptions budget;
};

// Its own fields, the KLT tracker's under klt_, the estimator's (with the VP detection in front)
// under estimator_, and of the components without a declaration of their own the fields that
// the node sets.
template <typename Visit>
void visit_fields(VisualOdometryOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(any_value(), o.use_lines, o.track_lines, o.line_flow, o.concurrent,
                  o.stereo_current_disparity, o.stereo_refine_tracks, o.use_direction_map,
                  o.anchor_orientation);
  visit("max_features", o.features.points.max_features, positive());
  visit_fields(o.klt, prefixed("klt_", visit));
  visit_fields(o.estimator, prefixed("estimator_", visit));
  HYBRID_VO_FIELDS(non_negative(), o.min_parallax_px, o.min_point_matches, o.min_line_matches);
  HYBRID_VO_FIELDS(any_value(), o.rotation_only_pairs, o.model_selection);
  HYBRID_VO_FIELDS(fraction(), o.keyframe_overlap);
  HYBRID_VO_FIELDS(non_negative(), o.keyframe_parallax_px, o.keyframe_min_points,
                  o.previous_keyframe_parallax_px, o.keyframe_max_turn_deg);
  visit("rotation_drift_floor_deg", o.orientation.drift_floor_deg, non_negative());
  visit("rotation_calibration_sigma", o.rotation_calibration_sigma, non_negative());
  visit("full_pair_turn_fraction", o.full_pair_turn_fraction, non_negative());
  visit("stereo_translation_margin", o.stereo_translation_margin, non_negative());
  visit("coast_blank_walls", o.orientation.coast_blank_walls);
  visit("translation_given_rotation", o.orientation.translation_given_rotation);
  HYBRID_VO_FIELDS(positive(), o.mono_scale);
  HYBRID_VO_FIELDS(non_negative(), o.mono_window_keyframes);
  visit("stereo_max_depth_baselines", o.stereo_scale.max_depth_baselines, non_negative());
  visit("stereo_offset_calibration", o.stereo_offset.enabled);
  visit_fields(o.budget, visit);
}

// Externally detected features of a frame (e.g. from a learned front end); ids link them across
// frames. Each modality present replaces the built-in one.
struct ExternalFeatures {
  bool has_points = false;
  std::vector<Eigen::Vector2d> points;  // pixels
  std::vector<int64_t> point_ids;
  bool points_undistorted = false;      // e.g. VINS-Mono publishes undistorted coordinates
  bool has_lines = false;
  std::vector<LineSegment> lines;
  std::vector<int64_t> line_ids;
  bool lines_undistorted = false;
};

struct VisualOdometryInput {
  double stamp = 0.0;
  cv::Mat image;                // left or mono, 8-bit
  CameraModel camera;
  cv::Mat right_image;          // rectified stereo partner, optional
  double baseline_m = 0.0;      // stereo baseline; > 0 with a right image gives metric scale
  ExternalFeatures external;
};

enum class VoStatus {
  kFirstFrame,      // initialised the keyframe, no motion yet
  kOk,              // motion estimated and integrated
  kLowParallax,     // too little motion to the keyframe and no rotation found; skipped
  kRotationOnly,    // no translation seen: the rotation to the keyframe (and stereo's t)
  kTooFewFeatures,  // re-initialised on this frame, no motion
  kNoPose,          // the estimator found no trustworthy pose; keyframe kept, no motion
  kInvalidInput,    // empty image, invalid camera; frame ignored
  kReset,           // time went backwards: state cleared, this frame is the new first frame
};
const char* to_string(VoStatus status);
// The frame has a pose to report: a motion (full or rotation-only), or the origin of a chain.
inline bool answered(VoStatus status) {
  return status == VoStatus::kOk || status == VoStatus::kRotationOnly ||
         status == VoStatus::kFirstFrame || status == VoStatus::kReset;
}

struct VisualOdometryResult {
  VoStatus status = VoStatus::kInvalidInput;
  std::string message;
  double reference_stamp = 0.0;  // the keyframe the frame was paired with
  // Mono: that keyframe is the one before the current (previous_keyframe_parallax_px): this
  // frame had too little parallax to the current one.
  bool paired_with_keyframe_before = false;
  // The KLT tracks' vignetting (KltTrackerOptions::correct_vignetting): V at the image's corners
  // as measured so far, and whether this frame was tracked on the image with it taken out.
  double vignetting_corner_gain = 1.0;
  bool vignetting_corrected = false;
  TwoViewEstimate estimate;
  RelativePose motion;           // X_cur = R X_ref + t, t scaled (metric when scale_known)
  bool scale_known = false;
  // kRotationOnly: the data showed no translation (rotation_only_pairs): t is zero in mono (its
  // covariance a pair's length, mono_scale, per axis) or measured from the stereo points
  // (scale_known). `parallax_px`: the points' median motion to the keyframe after the rotation
  // (-1 unknown); `became_keyframe`: the frame took the keyframe's place (else the next frame is
  // paired with the same keyframe: its parallax was too small for a baseline). `baseline`: the
  // translation is the pair's epipolar geometry's (its direction, and in stereo the scale's
  // length); else too little parallax for one: zero within mono_scale in mono, the stereo
  // points' in stereo.
  double parallax_px = -1.0;
  bool became_keyframe = false;
  bool baseline = false;
  // Covariance of [rotation (left increment, rad), t as in `motion`]: the estimator's, with the
  // translation block scaled and, with a stereo scale, its variance along t added.
  Eigen::Matrix<double, 6, 6> motion_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool motion_covariance_valid = false;
  // Stereo input: the scale fit and its inputs (inlier points of the keyframe with a disparity,
  // seen again). Without a usable fit t has the length mono_scale and scale_known is false.
  bool stereo_scale_attempted = false;
  StereoScaleEstimate stereo_scale;
  std::vector<StereoScaleObservation> scale_observations;
  // Mono: the keyframe points that gave the translation's length (relative scale; 0: none, the
  // length carried from the last pair's speed or mono_scale), or, without a baseline, that
  // measured the translation (translation_from_depths; else it is zero within mono_scale).
  int mono_scale_points = 0;
  bool translation_from_depths = false;
  // Mono, a frame becoming the keyframe: the window's points that fitted its link's length with
  // the last keyframes' (0: not fitted, the pair's own length).
  int window_scale_points = 0;
  double disparity_offset_px = 0.0;  // the offset applied (0 until self-calibration is sure)
  Eigen::Matrix3d R_wc = Eigen::Matrix3d::Identity();  // current camera into odometry
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();     // current camera centre in odometry
  // Of this pose (R_wc, centre), [position, rotation as a left increment of R_wc] in the odometry
  // frame (ROS's order, geometry/pose_covariance.h): the rotation block is the orientation's as
  // reported (VoOrientation::reported_covariance: the map's, with the pairs' correlated errors
  // bounded); the position is chained over the integrated pairs to first order, with its cross
  // terms. Without a metric scale the position is in the unit of the first pair with a baseline
  // (mono_scale) and holds the unit's drift: each keyframe hands its length's error on to all
  // later ones (propagate_scaled_pose_covariance). Zero at the first frame (and after a reset); a
  // restart keeps it, as it keeps the pose.
  Matrix6d pose_covariance = Matrix6d::Zero();
  int pose_covariance_gaps = 0;  // integrated pairs without a usable covariance, ever
  TwoViewMatches matches;        // the pair's matches (undistorted pixels) for drawing
  std::vector<int> vp_track_ids; // per VP match of the pair: the map direction of its prior, or -1
  // How the map of directions placed this frame (with use_direction_map): the orientation's source,
  // the directions each VP was paired with, blank wall, correction.
  OrientationEstimate orientation;
  int num_point_matches = 0, num_line_matches = 0;
  LineTrackingStats line_tracking;  // with track_lines
  // Wall clock: image to matches, VPs + estimator, the whole frame; and per stage.
  double frontend_ms = 0.0, estimator_ms = 0.0, total_ms = 0.0;
  StageTimings stages;
  int work_level = 0;               // the frame's work level (cpu_budget.h)
  double average_cpu_ms = 0.0;      // the budget's average CPU per frame, this one included
};

// Frame-to-frame visual odometry without ROS: front end (KLT or descriptors for points, LSD+LBD
// for segments), the hybrid estimator against the last keyframe, stereo scale, the VP tracker,
// and pose integration. The node only converts messages around it.
class VisualOdometry {
 public:
  explicit VisualOdometry(const VisualOdometryOptions& options = {});
  ~VisualOdometry();
  VisualOdometryResult process(const VisualOdometryInput& input);
  void reset();
  // Starts a new keyframe chain at the next frame but keeps the pose: after a fault in the stream
  // (a time gap, a new image size, rejected frames) the motion across it is unknown, so nothing
  // may be paired across it, yet the odometry goes on from where it was. The map of directions is
  // dropped too: its directions would be compared under a rotation that no longer holds.
  void restart();
  const DirectionMap& direction_map() const { return orientation_.direction_map(); }
  // The KLT tracks' cost and lifetimes so far (KLT tracking only).
  const KltTrackStats& point_track_stats() const { return klt_.stats(); }
  const VignettingEstimator& point_track_vignetting() const { return klt_.vignetting(); }
  const VisualOdometryOptions& options() const { return options_; }

 private:
  // A frame's stereo pair as LK pyramids (stereo_pyramid), each image's built once: the left one
  // is the KLT tracker's when it serves.
  struct StereoPair {
    std::vector<cv::Mat> left, right;
    PinholeCamera camera;
    double baseline_m = 0.0;
    bool valid() const { return !left.empty() && !right.empty(); }
  };

  // What the frames are paired with (vo_keyframe_policy.cc says when a frame becomes one).
  struct Keyframe {
    bool valid = false;
    double stamp = 0.0;
    std::map<int64_t, Eigen::Vector2d> points;          // id -> distorted pixel
    std::map<int64_t, Eigen::Vector3d> points3d;        // id -> stereo point (metres, camera)
    std::map<int64_t, InverseDepth> depths;             // mono: id -> inverse depth (camera)
    // Mono: what it knew as it became the keyframe (carried over and from its own pair), and each
    // point's surest triangulation from the pairs with it since; depths fuses the two.
    std::map<int64_t, InverseDepth> made_depths, pair_depths;
    // Mono, the first keyframe while none of its points has a usable depth: its first pair with a
    // baseline's parallax after the rotation and length (0: none yet).
    double unit_parallax = 0.0, unit_length = 0.0;
    ImageFeatures features;                             // segments (and descriptor points)
    std::map<int64_t, LineSegment> external_lines;      // id -> segment
    std::map<int64_t, LineSegment> tracked_lines;       // LineTracker id -> segment
    bool points_undistorted = false, lines_undistorted = false;
    CameraModel camera;
    cv::Mat image;  // grey, kept for the scale's track refinement (stereo input only)
    // KLT tracking with stereo: the features new in this frame get their stereo points only once
    // they are tracked into a later frame (complete_keyframe_stereo), from this pair: on KITTI
    // two thirds of them are lost at their first track. The points are those an eager match
    // would give, a new feature having no disparity to start its search from either way.
    StereoPair stereo;
    std::vector<int64_t> stereo_pending;
    Eigen::Matrix3d R_wc = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d R_wc_covariance = Eigen::Matrix3d::Zero();  // left increment, odometry frame
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    // Its pose's, with the log-scale of a mono unit (PoseCovarianceChain::scaled_covariance).
    Matrix7d pose_covariance = Matrix7d::Zero();
    int paired_points = -1;  // point matches of the first frame paired with it
  };

  // The stereo matching of features by id (the searches are left to the caller).
  struct StereoFeatures {
    std::vector<int64_t> ids;
    std::unique_ptr<StereoMatcher> matcher;
    std::map<int64_t, Eigen::Vector3d> points() const;  // once every chunk is searched
  };

  // One frame's state on its way through run_frame (vo_frame.h).
  struct Frame;

  // process() without the threads' CPU times (not named process*: callgrind's
  // --toggle-collect='hybrid_vo::VisualOdometry::process*' would toggle twice). The frame's
  // schedule: its stages in order, and which thread runs each.
  VisualOdometryResult run_frame(const VisualOdometryInput& input);

  // The stages, by file. visual_odometry.cc: the input checked (time going backwards resets),
  // the image converted to grey once, the segments' motion predicted (false: invalid input);
  // the orientation (VoOrientation) and the pose integrated.
  bool begin_frame(Frame& f);
  void orient(Frame& f);
  void integrate(Frame& f);
  // The frame's end for a pair without a baseline that leaves the keyframe in place: its pose is
  // reported (the keyframe's position moved by the pair's t, the pair's orientation) and nothing
  // is taken on.
  VisualOdometryResult answer_without_keyframe(Frame& f);

  // vo_tracking.cc: the frame's points and segments, their matches with the keyframe's, and the
  // KLT re-detection for the next frame.
  // The frame's image pyramid, which the KLT tracker, the segments' flow and the stereo
  // matching share (built when one of them needs it).
  void build_pyramid(Frame& f) const;
  void track_segments(Frame& f);      // detected, described and tracked (the second thread)
  // line_flow: the frame's segments detected on the second thread where the tracks want them,
  // beside the points; then, once the points are tracked, the tracks followed by the flow (on
  // both threads) and the detections taken on.
  void start_segment_detection(Frame& f);
  void follow_segments(Frame& f);
  void track_points(Frame& f);        // KLT (searches on both threads), external or descriptors
  void match_points(Frame& f) const;  // with the keyframe's, and the parallax
  void start_redetection(Frame& f);   // its cells shared by both threads
  void finish_redetection(Frame& f);
  void match_segments(Frame& f) const;
  // The work level's options for the trackers and the segments (cpu_budget.h).
  void apply_work_level(int level);
  // Every feature the KLT tracker holds, by id.
  std::map<int64_t, Eigen::Vector2d> klt_points() const;

  // vo_keyframe_policy.cc: whether a frame is estimated, becomes the keyframe or is left out.
  enum class Pairing {
    kEstimate,     // estimated against the keyframe; kept as the next one when a pose is found
    kNewKeyframe,  // the keyframe from now on, without a motion: first frame, too few matches
    kSkip,         // left out, the keyframe staying: too little parallax
    // Estimated and answered, the keyframe staying while its points are seen: too little
    // parallax for a baseline (rotation_only_pairs)
    kEstimateKeepKeyframe,
  };
  bool low_parallax(const Frame& f) const;
  Pairing decide_keyframe(Frame& f);
  // A frame leaves the keyframe in place while its parallax is short of keyframe_parallax_px (or
  // it has no baseline) and enough of the keyframe's points are seen.
  bool keeps_keyframe(const Frame& f) const;
  // Mono, a frame that keeps the keyframe with less than previous_keyframe_parallax_px: matched
  // and estimated against the keyframe before, which stands in as keyframe_ until the frame ends.
  // False, and the frame as it was, where that gives no pair with more parallax and a baseline.
  bool estimate_against_previous_keyframe(Frame& f, Pairing pairing);
  VisualOdometryResult keep_as_keyframe(Frame& f);  // the frame's end: it becomes the keyframe
  VisualOdometryResult skip_frame(Frame& f);        // the frame's end: the keyframe stays
  // `points` with their stereo points matched so far; `pending` the ids still without (see
  // Keyframe::stereo_pending).
  void make_keyframe(Frame& f, std::map<int64_t, Eigen::Vector2d> points,
                     std::vector<int64_t> pending);

  // vo_mono_scale.cc: in mono, the inverse depths a frame becoming the keyframe knows of its
  // points (from its pair with the keyframe before, and carried over from it); the relative scale
  // of a pair with a baseline from its keyframe's (false: none found).
  std::map<int64_t, InverseDepth> keyframe_depths(const Frame& f) const;
  bool fit_mono_scale(Frame& f, double* scale, double* sigma) const;
  // The keyframe's inlier points with a depth known to mono_depth_max_sigma, as the stereo fits
  // read them (a rig of baseline 1), and those fits' options for them.
  std::vector<StereoScaleObservation> depth_observations(const Frame& f) const;
  StereoScaleOptions depth_fit_options() const;
  // A pair with a baseline whose keyframe knows too few depths: its length from the last pair's
  // speed, or before any from its parallax against the first such pair's (mono_scale), and its
  // sigma (*sigma: none for the odometry's very first, which is the unit).
  double mono_length_without_depths(const Frame& f, double* sigma);
  // A pair without a baseline: its translation from the keyframe's depths with its rotation held
  // (false: too few agree; t stays zero within mono_scale).
  bool measure_mono_translation(Frame& f) const;
  // A pair with a baseline that leaves the keyframe in place: its points triangulated in the
  // keyframe, each kept where surer than its pairs' before.
  void refine_keyframe_depths(const Frame& f);

  // vo_scale_window.cc: in mono, the last keyframes (each frame that becomes one is remembered
  // with its rays and its link) and the fit of a new link's length with theirs.
  std::map<int64_t, Eigen::Vector2d> keyframe_rays() const;  // normalised, undistorted, by id
  void remember_window_keyframe(const Frame& f);
  void fit_window_scale(Frame& f);

  // vo_estimation.cc: the pair's matches undistorted, its VPs and their priors; its full pose
  // (false: none found), which may yet show no translation (f.rotation_only); or its rotation
  // alone (false: none found).
  TwoViewOptions pair_options() const;
  void prepare_pair(Frame& f);
  bool estimate(Frame& f);
  bool estimate_rotation(Frame& f);

  // vo_stereo_scale.cc: the stereo points of the frame and the keyframe, and the scale.
  void build_stereo_pyramids(Frame& f) const;  // the second thread
  void start_stereo(Frame& f);    // the searches, shared by both threads
  void finish_stereo(Frame& f);   // (starts them if need be)
  void observe_scale(Frame& f) const;
  void fit_scale(Frame& f);
  // A pair without a baseline, or with a rotation alone: in stereo its rotation and translation
  // from the keyframe's stereo points (the rotation alone would take in a translation its points
  // cannot show), into the estimate before it is oriented; then its translation (stereo's, or
  // zero within mono_scale: only a baseline moves a mono position).
  void measure_stereo_motion(Frame& f);
  void fit_translation_without_baseline(Frame& f);
  // A pair with a baseline: its translation (the oriented pose's direction) at this length, its
  // covariance the estimator's with the length's sigma along it (kept in the frame).
  void set_length(Frame& f, double scale, double sigma);
  // A pair with a baseline in stereo: the stereo points' translation where it is clearly better
  // (stereo_translation_margin).
  void prefer_stereo_translation(Frame& f);
  // Of `points` (by id) in `pair`. With `predict` each search starts at the disparity of the
  // same id in the keyframe, when it has one.
  StereoFeatures stereo_features(const StereoPair& pair,
                                 const std::map<int64_t, Eigen::Vector2d>& points,
                                 bool predict) const;
  // The keyframe's pending stereo points of the features among `tracked`, on both threads
  // (timed by `clock`); the others can never be matched again, and leave the pending list.
  void complete_keyframe_stereo(const std::map<int64_t, Eigen::Vector2d>& tracked,
                                WorkClock* clock);
  // The scale's observations of an estimated pair: the keyframe's stereo points among the
  // pose's point inliers, seen again; `observed` receives their ids.
  std::vector<StereoScaleObservation> scale_observations(const Frame& f,
                                                         std::vector<int64_t>* observed) const;
  // Their current points (of KLT tracks `observed`, at f.points in this frame) re-tracked from
  // the keyframe with an affine window (refine_tracks_affine), on both threads; the near ones
  // that cannot be are left out (of `observed` too).
  std::vector<StereoScaleObservation> refine_scale_points(
      const Frame& f, std::vector<int64_t>* observed,
      std::vector<StereoScaleObservation> observations) const;
  // This frame's disparities of the observations of f.observed (stereo_current_disparity),
  // where f.points3d has them.
  void add_current_disparities(Frame& f) const;

  VisualOdometryOptions options_;
  std::unique_ptr<WorkerThread> worker_;
  KltTracker klt_;
  LineTracker line_tracker_;
  LineFlowTracker line_flow_;
  VoOrientation orientation_;
  // Kept across reset(): the offset belongs to the rig, not to the trajectory.
  DisparityOffsetFilter offset_filter_;
  Keyframe keyframe_;
  Keyframe previous_keyframe_;  // the one keyframe_ replaced (mono, made by a pair), or invalid
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  PoseCovarianceChain pose_covariance_;
  double last_stamp_ = -1e300;
  // The last frame answered with a pose (rotation-only frames included): the rotation rate.
  double last_answer_stamp_ = -1e300;
  // Mono: the last pair's translation length per second, for a pair whose keyframe knows no
  // depths (negative: none yet).
  double mono_speed_ = -1.0;
  // Mono: the last keyframes, oldest first, the current one last (mono_window_keyframes - 1 of
  // them): each one's points' rays and the link from the one before (X = R X_before + t, its
  // length as the last window fitted it).
  struct WindowKeyframe {
    std::map<int64_t, Eigen::Vector2d> rays;
    RelativePose link;
    bool sure = false;  // the link had a baseline with a direction known to a few degrees
  };
  std::deque<WindowKeyframe> window_;
  Eigen::Matrix3d last_answer_R_wc_ = Eigen::Matrix3d::Identity();
  // Kept across reset(): the machine's load does not change with the trajectory.
  CpuBudget budget_;
  // The work level's (apply_work_level): the segments' detection and description, and the share
  // of the point budget the KLT tracker keeps.
  LineMatchingOptions segment_options_;
  double point_share_ = 1.0;
};

}  // namespace hybrid_vo
