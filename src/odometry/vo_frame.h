#pragma once

// Internal: one frame's state on its way through VisualOdometry::run_frame.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

#include "hybrid_vo/estimation/stereo_motion.h"
#include "hybrid_vo/features/gray_image.h"
#include "hybrid_vo/odometry/visual_odometry.h"

namespace hybrid_vo {

// How much less sure than mono_depth_max_direction_sigma a direction may be for the depths of a
// keyframe that knew none (the hand-held room's first pair with a baseline: 5.3 degrees), for a
// length fitted to depths, and for two keyframes to be a baseline apart.
constexpr double kLooseDirectionFactor = 3.0;

// The largest standard deviation of a pair's translation direction (radians; infinite without
// one).
inline double translation_direction_sigma(const VisualOdometryResult& r) {
  const double length = r.motion.t.norm();
  if (!(length > 0.0)) return INFINITY;
  const Eigen::Matrix3d C = r.motion_covariance.bottomRightCorner<3, 3>() / (length * length);
  if (!all_finite(C)) return INFINITY;
  return std::sqrt(std::max(0.0, C.trace()));
}

// What the stages of one frame read and write, in the order run_frame runs them; the result is
// filled on the way. The second thread's handles come last: leaving the frame early destroys
// them first, which waits for their work, and that uses the fields above.
struct VisualOdometry::Frame {
  explicit Frame(const VisualOdometryInput& in) : input(in) {}
  Frame(const Frame&) = delete;
  Frame& operator=(const Frame&) = delete;

  const VisualOdometryInput& input;
  const std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  VisualOdometryResult result;  // what process() returns; result.matches are the pair's
  bool was_reset = false;       // time went backwards: the odometry starts again here

  // The frame as it came in (begin_frame).
  GrayImage gray;            // the image, converted once: every stage takes this form
  bool tracking = false;     // points are KLT tracks (not external, not descriptors)
  bool stereo = false;       // a right image with a baseline: metric scale
  bool klt_pyramid = false;  // the KLT tracker's pyramid of the image serves the stereo matching
  // Its vignetting correction (KltTracker::flat_field_gain), which the right image then takes too.
  cv::Mat flat_field_gain;
  std::vector<cv::Mat> pyramid;  // the image's (build_pyramid), or empty
  // How the segments move from the last frame as the camera turns at its last rate.
  Eigen::Matrix3d segment_motion = Eigen::Matrix3d::Identity();

  // Its features and their matches with the keyframe's (in result.matches).
  std::map<int64_t, Eigen::Vector2d> points;  // by id; the tracked ones until re-detection
  ImageFeatures features;                     // segments (and descriptor points)
  std::vector<int64_t> line_ids;              // with track_lines: the track of each segment
  // With line_flow: the KLT tracks' motion into this frame, which predicts the segments'; and
  // the frame's detected segments (oriented), when the tracks want them.
  std::vector<PointMatch> point_motion;
  bool detect_segments = false;
  std::vector<LineSegment> detected_segments;
  double detection_ms = 0.0;
  std::vector<int64_t> point_ids;             // per point match: its id
  // The median transfer error of the point matches under the rotation that best explains them
  // (the parallax after the rotation), or their median motion where no rotation was found;
  // -1 below 5 matches.
  double parallax = -1.0;
  // That rotation, from the points alone (match_points), then from every modality for a pair
  // answered with its rotation alone (estimate_rotation).
  RotationOnlyEstimate rotation;
  bool rotation_only = false;  // the pair is answered with its rotation alone
  bool baseline = true;        // its parallax after the rotation makes a baseline
  // Stereo, without a baseline or with a rotation alone: the motion from the stereo points.
  StereoMotionEstimate stereo_motion;

  // Stereo: the pair's pyramids, the frame's stereo points, the scale's observations.
  StereoPair pair;
  StereoFeatures current_stereo;
  WorkClock stereo_clock;
  bool stereo_started = false, stereo_finished = false;
  std::map<int64_t, Eigen::Vector3d> points3d;  // the frame's stereo points, once finished
  std::vector<StereoScaleObservation> scale_observations;
  std::vector<int64_t> observed;  // the ids of the scale's observations

  // The pair's orientation (orient): whether the estimator looked for VPs, and the outcome.
  bool vps_detected = false;
  VoOrientation::Oriented oriented;

  // A pair with a baseline (fit_scale): the covariance of its motion with a unit translation, and
  // the length given to it with its sigma (set_length).
  Eigen::Matrix<double, 6, 6> unit_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  double length = 0.0, length_sigma = 0.0;
  // What a mono pair hands on to the depths it triangulates, as variances of the unit's
  // log-scale: its relative length error, and as much again as its direction is off per axis (a
  // direction off by d radians stretches the depths of a scene spread over the image by about d:
  // the hand-held room's first keyframe, triangulated by a pair 5.8 degrees off, changed its unit
  // by 5 % once surer pairs took over).
  double length_variance() const {
    const double relative = length > 0.0 ? length_sigma / length : 0.0;
    return relative * relative;
  }
  double direction_variance() const {
    const double direction = translation_direction_sigma(result);
    return std::isfinite(direction) ? 0.5 * direction * direction : 0.0;
  }

  // The KLT re-detection for the next frame.
  KltDetection detection;
  WorkClock redetect_clock;

  // The second thread's work (see above).
  WorkerJob pyramids_job, segments_job, detection_job;
  SharedLoop stereo_loop, redetection;
};

}  // namespace hybrid_vo
