// VisualOdometry's features: the frame's points (KLT tracks, external or detected) and segments
// (detected, described and tracked), their matches with the keyframe's, and the KLT
// re-detection for the next frame.
#include <algorithm>
#include <chrono>

#include <opencv2/video/tracking.hpp>

#include "vo_frame.h"

namespace hybrid_vo {
namespace {

// The median image motion of the point matches (pixels).
double median_motion_px(const std::vector<PointMatch>& matches) {
  std::vector<double> motion;
  for (const PointMatch& p : matches) motion.push_back((p.x2 - p.x1).norm());
  std::nth_element(motion.begin(), motion.begin() + motion.size() / 2, motion.end());
  return motion[motion.size() / 2];
}

}  // namespace

std::map<int64_t, Eigen::Vector2d> VisualOdometry::klt_points() const {
  std::map<int64_t, Eigen::Vector2d> points;
  for (size_t i = 0; i < klt_.points().size(); ++i)
    points[klt_.ids()[i]] = Eigen::Vector2d(klt_.points()[i].x, klt_.points()[i].y);
  return points;
}

void VisualOdometry::apply_work_level(int level) {
  const KltTrackerOptions& klt = options_.klt;
  point_share_ = level >= 4 ? 0.5 : 1.0;
  const int max_features = options_.features.points.max_features;
  klt_.set_work(std::max(1, static_cast<int>(point_share_ * max_features)),
                level >= 2 ? std::max(0.5, klt.redetect_min_missing) : klt.redetect_min_missing,
                level >= 1 || klt.redetect_alternate);
  line_tracker_.set_reidentify(level < 2 && options_.line_tracking.reidentify);
  // Without segment tracking the descriptors are what matches the segments: they stay.
  segment_options_ = options_.features.lines;
  segment_options_.description.describe =
      (level < 3 || !options_.track_lines) && segment_options_.description.describe;
}

void VisualOdometry::build_pyramid(Frame& f) const {
  const auto start = std::chrono::steady_clock::now();
  const bool flow = options_.use_lines && options_.track_lines && options_.line_flow &&
                    !f.input.external.has_lines;
  if (f.tracking) {
    f.result.vignetting_corrected = !klt_.flat_field_gain().empty();
    f.pyramid = klt_.build_pyramid(f.gray);
  } else if (flow) {
    const int window = options_.klt.window_px;
    cv::buildOpticalFlowPyramid(f.gray.mat(), f.pyramid, cv::Size(window, window),
                                options_.line_flow_tracking.flow.levels, false);
  }
  f.result.stages.points_ms += ms_since(start);
}

void VisualOdometry::track_segments(Frame& f) {
  const auto lines_start = std::chrono::steady_clock::now();
  f.features.lines = detect_line_features(f.gray, segment_options_);
  if (options_.track_lines)
    f.line_ids = line_tracker_.track(f.features.lines, f.input.stamp, &f.result.line_tracking,
                                     f.segment_motion);
  f.result.line_tracking.detected = true;
  f.result.stages.lines_ms = ms_since(lines_start);
}

void VisualOdometry::start_segment_detection(Frame& f) {
  // Without descriptors: the flow's tracks match nothing by them.
  f.detect_segments = line_flow_.wants_detection();
  if (!f.detect_segments) return;
  f.detection_job = worker_->submit([this, &f] {
    const auto start = std::chrono::steady_clock::now();
    LineDescriptionOptions oriented = segment_options_.description;
    oriented.describe = false;
    f.detected_segments =
        describe_line_segments(f.gray, detect_line_segments(f.gray, segment_options_.detection),
                               nullptr, oriented)
            .segments;
    f.detection_ms = ms_since(start);
  });
}

void VisualOdometry::follow_segments(Frame& f) {
  const auto start = std::chrono::steady_clock::now();
  const PointFlowField points(f.point_motion);
  line_flow_.track(pyramid_images(f.pyramid), f.input.stamp, f.segment_motion, &points,
                   worker_->parallel(), &f.result.line_tracking);
  f.detection_job.get();
  if (f.detect_segments) {
    line_flow_.add_detections(f.detected_segments, &f.result.line_tracking);
    f.result.line_tracking.detected = true;
  }
  f.features.lines.segments = line_flow_.segments();
  f.line_ids = line_flow_.ids();
  f.result.stages.lines_ms = f.detection_ms + ms_since(start);
}

void VisualOdometry::track_points(Frame& f) {
  const ExternalFeatures& external = f.input.external;
  const auto points_start = std::chrono::steady_clock::now();
  const double pyramid_ms = f.result.stages.points_ms;
  if (external.has_points) {
    for (size_t i = 0; i < external.points.size() && i < external.point_ids.size(); ++i)
      if (all_finite(external.points[i])) f.points[external.point_ids[i]] = external.points[i];
  } else if (f.tracking) {
    // The searches on both threads, the second once it has detected the segments.
    f.point_motion = klt_.track_pyramid(f.pyramid, f.gray, nullptr, f.input.stamp,
                                        worker_->parallel());
    f.result.vignetting_corner_gain = klt_.vignetting().corner_gain();
    f.points = klt_points();
    if (f.klt_pyramid) f.pair.left = klt_.pyramid();
  } else {
    f.features.points = detect_point_features(f.gray, options_.features.points);
    const std::vector<cv::KeyPoint>& keypoints = f.features.points.keypoints;
    for (size_t i = 0; i < keypoints.size(); ++i)
      f.points[static_cast<int64_t>(i)] = Eigen::Vector2d(keypoints[i].pt.x, keypoints[i].pt.y);
  }
  f.result.stages.points_ms = pyramid_ms + ms_since(points_start);
}

void VisualOdometry::match_points(Frame& f) const {
  if (!keyframe_.valid) return;
  // By track id, or by descriptor (descriptor points: their ids are keyframe indices).
  std::vector<PointMatch>& matches = f.result.matches.points;
  if (!f.input.external.has_points && !f.tracking) {
    std::vector<std::pair<int, int>> pairs;
    matches = match_point_features(keyframe_.features.points, f.features.points,
                                   options_.features.points, &pairs);
    for (const auto& p : pairs) f.point_ids.push_back(p.first);
  } else {
    for (const auto& [id, p] : f.points) {
      const auto it = keyframe_.points.find(id);
      if (it == keyframe_.points.end()) continue;
      matches.push_back({it->second, p});
      f.point_ids.push_back(id);
    }
  }
  // Whether the frame moved enough to be estimated (low_parallax): the parallax the rotation that
  // best explains the points leaves (a pan's motion is no baseline), else their motion.
  if (matches.size() < 5) return;
  f.parallax = median_motion_px(matches);
  TwoViewMatches points;
  points.points = matches;
  if (!(f.input.external.has_points && f.input.external.points_undistorted &&
        keyframe_.points_undistorted))
    undistort_matches(keyframe_.camera, f.input.camera, &points);
  RotationOnlyOptions options = options_.rotation_only;
  options.use_lines = options.use_vps = false;
  // The parallax is below min_parallax_px only when over half the points fit a rotation within
  // its threshold: a rotation with half the points as inliers is drawn in 50 samples but once in
  // a hundred thousand (a forward drive has far fewer, and would use up every draw).
  options.max_iterations = std::min(options.max_iterations, 50);
  f.rotation = estimate_rotation_only(keyframe_.camera.pinhole, f.input.camera.pinhole, points,
                                      options, options_.estimator.covariance);
  if (f.rotation.ok && f.rotation.parallax_px >= 0.0) f.parallax = f.rotation.parallax_px;
  f.result.parallax_px = f.parallax;
}

void VisualOdometry::start_redetection(Frame& f) {
  // The re-detection serves only the next frame: cell by cell on the second thread while this
  // one estimates and fits the scale, and this one takes the cells left when it is done.
  // f.points holds the tracked features until then.
  if (!f.tracking) return;
  f.detection = klt_.plan_detection();
  f.redetection = worker_->share(f.detection.cells(), f.redetect_clock.timed([this, &f](int cell) {
    klt_.detect_cell(&f.detection, cell);
  }));
}

void VisualOdometry::finish_redetection(Frame& f) {
  f.redetection.join();
  if (f.tracking) klt_.add_detections(f.detection);
  f.result.stages.redetect_ms = f.redetect_clock.ms();
}

void VisualOdometry::match_segments(Frame& f) const {
  VisualOdometryResult& r = f.result;
  TwoViewMatches& m = r.matches;
  const ExternalFeatures& external = f.input.external;
  if (external.has_lines) {
    for (size_t i = 0; i < external.lines.size() && i < external.line_ids.size(); ++i) {
      const auto it = keyframe_.external_lines.find(external.line_ids[i]);
      if (it != keyframe_.external_lines.end()) m.lines.push_back({it->second, external.lines[i]});
    }
  } else if (options_.use_lines) {
    const auto matching_start = std::chrono::steady_clock::now();
    if (options_.track_lines) {
      for (size_t i = 0; i < f.line_ids.size(); ++i) {
        const auto it = keyframe_.tracked_lines.find(f.line_ids[i]);
        if (it != keyframe_.tracked_lines.end())
          m.lines.push_back({it->second, f.features.lines.segments[i]});
      }
    } else {
      m.lines = match_line_features(keyframe_.features.lines, f.features.lines,
                                    options_.features.lines);
    }
    r.stages.line_matching_ms = ms_since(matching_start);
  }
  r.num_point_matches = static_cast<int>(m.points.size());
  r.num_line_matches = static_cast<int>(m.lines.size());
  r.frontend_ms = ms_since(f.start);
}

}  // namespace hybrid_vo
