#include "hybrid_vo/frontend/visual_odometry.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/geometry/vp_covariance.h"
#include "hybrid_vo/frontend/gray_image.h"

namespace hybrid_vo {
namespace {

// The VPs of one image of a pair as tracker observations: each direction with the covariance of
// its fit to that image's labelled segments (pixels, at `sigma_px` per segment) plus `vp_sigma_deg`
// per axis, the pair's measured VP scale: the fit alone is optimistic (rendered corridor: the fit
// says 0.02-0.1 degrees, the VPs are 0.05-0.3 degrees off the true axes).
std::vector<VpObservation> vp_observations(const Eigen::Matrix3d& K, const TwoViewMatches& m,
                                           bool second_image, double sigma_px,
                                           double vp_sigma_deg) {
  std::vector<std::vector<LineSegment>> segments(m.vps.size());
  for (size_t i = 0; i < m.lines.size() && i < m.line_vp.size(); ++i)
    if (m.line_vp[i] >= 0 && m.line_vp[i] < static_cast<int>(m.vps.size()))
      segments[m.line_vp[i]].push_back(second_image ? m.lines[i].s2 : m.lines[i].s1);
  std::vector<VpObservation> observations(m.vps.size());
  for (size_t k = 0; k < m.vps.size(); ++k) {
    observations[k].direction = second_image ? m.vps[k].d2 : m.vps[k].d1;
    // Without a usable fit the covariance stays zero: the tracker's default sigma.
    Eigen::Matrix3d covariance;
    if (vp_measurement_covariance(K, segments[k], observations[k].direction, sigma_px,
                                  vp_sigma_deg * M_PI / 180.0, &covariance))
      observations[k].covariance = covariance;
  }
  return observations;
}

// The median image motion of the point matches (pixels).
double median_motion_px(const std::vector<PointMatch>& matches) {
  std::vector<double> motion;
  for (const PointMatch& p : matches) motion.push_back((p.x2 - p.x1).norm());
  std::nth_element(motion.begin(), motion.begin() + motion.size() / 2, motion.end());
  return motion[motion.size() / 2];
}

bool uses_vps(const RelativePoseEstimatorOptions& options) {
  for (const SolverInfo& info : solver_table())
    if (options.ransac.enabled[static_cast<int>(info.id)] && info.num_vps > 0) return true;
  return false;
}

}  // namespace

VisualOdometryOptions::VisualOdometryOptions() {
  features.points = video_point_matching_options();
  features.lines = video_line_matching_options();
  // Low texture (issue 30, doc/low_texture.md): a VP may rest on three long segments, and
  // segments that stop short of a corner still meet.
  estimator.vp_detection.min_long_inliers = 3;
  estimator.vp_detection.min_support_px = 150.0;
  estimator.junctions.length_fraction = 0.15;
  // A scene direction does not go away: a track survives a few seconds unseen, and is not dropped
  // for disagreeing with the odometry, which is what it exists to correct (anchor_orientation).
  vp_tracker.max_misses = 60;
  vp_tracker.max_gate_failures = 0;
}

const char* to_string(VoStatus status) {
  switch (status) {
    case VoStatus::kFirstFrame:
      return "first frame";
    case VoStatus::kOk:
      return "ok";
    case VoStatus::kLowParallax:
      return "low parallax";
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
      vp_tracker_(options.vp_tracker),
      offset_filter_(options.stereo_offset) {}

VisualOdometry::~VisualOdometry() = default;

std::map<int64_t, Eigen::Vector2d> VisualOdometry::klt_points() const {
  std::map<int64_t, Eigen::Vector2d> points;
  for (size_t i = 0; i < klt_.points().size(); ++i)
    points[klt_.ids()[i]] = Eigen::Vector2d(klt_.points()[i].x, klt_.points()[i].y);
  return points;
}

void VisualOdometry::reset() {
  restart();
  R_wc_.setIdentity();
  R_wc_covariance_.setZero();
  centre_.setZero();
  last_stamp_ = -1e300;
}

void VisualOdometry::restart() {
  angular_velocity_.setZero();
  klt_.reset();
  line_tracker_.reset();
  vp_tracker_.reset();
  keyframe_ = Keyframe();
  tracker_seeded_ = false;
}

std::map<int64_t, Eigen::Vector3d> VisualOdometry::StereoFeatures::points() const {
  std::map<int64_t, Eigen::Vector3d> points3d;
  if (!matcher) return points3d;
  std::vector<char> valid;
  const std::vector<Eigen::Vector3d> X = matcher->points(&valid);
  for (size_t i = 0; i < ids.size(); ++i)
    if (valid[i]) points3d[ids[i]] = X[i];
  return points3d;
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

void VisualOdometry::match_points(const std::map<int64_t, Eigen::Vector2d>& points,
                                  const ImageFeatures& features, bool descriptors,
                                  TwoViewMatches* m, std::vector<int64_t>* point_ids) const {
  if (descriptors) {
    std::vector<std::pair<int, int>> pairs;
    m->points = match_point_features(keyframe_.features.points, features.points,
                                     options_.features.points, &pairs);
    for (const auto& p : pairs) point_ids->push_back(p.first);
    return;
  }
  for (const auto& [id, p] : points) {
    const auto it = keyframe_.points.find(id);
    if (it == keyframe_.points.end()) continue;
    m->points.push_back({it->second, p});
    point_ids->push_back(id);
  }
}

void VisualOdometry::make_keyframe(const VisualOdometryInput& input, const cv::Mat& gray,
                                   const std::map<int64_t, Eigen::Vector2d>& points,
                                   std::map<int64_t, Eigen::Vector3d> points3d,
                                   ImageFeatures features, const std::vector<int64_t>& line_ids,
                                   StereoPair stereo, std::vector<int64_t> pending) {
  keyframe_ = Keyframe();
  keyframe_.valid = true;
  keyframe_.stamp = input.stamp;
  keyframe_.points = points;
  keyframe_.points3d = std::move(points3d);
  keyframe_.stereo = std::move(stereo);
  keyframe_.stereo_pending = std::move(pending);
  for (size_t i = 0; i < line_ids.size() && i < features.lines.segments.size(); ++i)
    keyframe_.tracked_lines[line_ids[i]] = features.lines.segments[i];
  keyframe_.features = std::move(features);
  keyframe_.camera = input.camera;
  // A copy: the caller may reuse its image buffer for the next frame.
  if (options_.stereo_refine_tracks && !input.right_image.empty()) keyframe_.image = gray.clone();
  keyframe_.R_wc = R_wc_;
  keyframe_.R_wc_covariance = R_wc_covariance_;
  keyframe_.centre = centre_;
  if (input.external.has_lines)
    for (size_t i = 0; i < input.external.lines.size() && i < input.external.line_ids.size(); ++i)
      keyframe_.external_lines[input.external.line_ids[i]] = input.external.lines[i];
  keyframe_.points_undistorted = input.external.has_points && input.external.points_undistorted;
  keyframe_.lines_undistorted = input.external.has_lines && input.external.lines_undistorted;
}

std::vector<StereoScaleObservation> VisualOdometry::scale_observations(
    const VisualOdometryInput& input, const cv::Mat& gray, const TwoViewMatches& m,
    const std::vector<int64_t>& point_ids, const std::vector<char>& inliers,
    const std::map<int64_t, Eigen::Vector2d>& points, bool tracking,
    std::vector<int64_t>* observed) const {
  std::vector<StereoScaleObservation> observations;
  std::vector<int64_t>& ids = *observed;
  ids.clear();
  // The points were triangulated as Z = fx b / d.
  const double fx_baseline = keyframe_.camera.pinhole.fx * input.baseline_m;
  for (size_t i = 0; i < m.points.size() && i < point_ids.size(); ++i) {
    if (i >= inliers.size() || !inliers[i]) continue;
    const auto it = keyframe_.points3d.find(point_ids[i]);
    if (it == keyframe_.points3d.end()) continue;
    StereoScaleObservation o;
    o.x_ref = keyframe_.camera.pinhole.normalize(m.points[i].x1);
    o.disparity_ref = fx_baseline / it->second.z();
    o.x_cur = input.camera.pinhole.normalize(m.points[i].x2);
    observations.push_back(o);
    ids.push_back(point_ids[i]);
  }
  if (!tracking || !options_.stereo_refine_tracks || keyframe_.image.empty()) return observations;
  return refine_scale_points(input, gray, points, &ids, std::move(observations));
}

void VisualOdometry::add_current_disparities(
    const VisualOdometryInput& input, const std::vector<int64_t>& ids,
    const std::map<int64_t, Eigen::Vector3d>& current3d,
    std::vector<StereoScaleObservation>* observations) const {
  if (!options_.stereo_current_disparity) return;
  const double fx_baseline = input.camera.pinhole.fx * input.baseline_m;
  for (size_t k = 0; k < ids.size() && k < observations->size(); ++k) {
    const auto now = current3d.find(ids[k]);
    if (now != current3d.end()) (*observations)[k].disparity_cur = fx_baseline / now->second.z();
  }
}

std::vector<StereoScaleObservation> VisualOdometry::refine_scale_points(
    const VisualOdometryInput& input, const cv::Mat& gray,
    const std::map<int64_t, Eigen::Vector2d>& points, std::vector<int64_t>* observed,
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
    to.push_back(points.at(ids[k]));
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
        keyframe_.image, gray, chunk_from, &chunk_to, options_.stereo_track_refinement);
    std::copy(chunk_to.begin(), chunk_to.end(), to.begin() + begin);
    std::copy(chunk_refined.begin(), chunk_refined.end(), refined.begin() + begin);
  });
  // A track that cannot be refined is left out: on the corridor those lag by 0.57 px on
  // average, mostly windows at the image's border and lost tracks.
  std::vector<char> keep(observations.size(), 1);
  for (size_t j = 0; j < near.size(); ++j) {
    keep[near[j]] = refined[j];
    if (refined[j])
      observations[near[j]].x_cur = input.camera.pinhole.normalize(
          input.camera.has_distortion() ? input.camera.undistort(to[j]) : to[j]);
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

VisualOdometryResult VisualOdometry::process(const VisualOdometryInput& input) {
  const double caller_cpu_start = thread_cpu_ms(), worker_cpu_start = worker_->cpu_ms();
  VisualOdometryResult r = run_frame(input);
  // Each thread's CPU time for this frame: every job of the frame is done by now.
  r.stages.caller_cpu_ms = thread_cpu_ms() - caller_cpu_start;
  r.stages.worker_cpu_ms = worker_->cpu_ms() - worker_cpu_start;
  return r;
}

VisualOdometryResult VisualOdometry::run_frame(const VisualOdometryInput& input) {
  const auto start = std::chrono::steady_clock::now();
  VisualOdometryResult r;
  r.R_wc = R_wc_;
  r.centre = centre_;
  if (input.image.empty() || !input.camera.valid() || !std::isfinite(input.stamp)) {
    r.status = VoStatus::kInvalidInput;
    r.message = input.image.empty() ? "empty image" : "invalid camera or stamp";
    return r;
  }
  bool was_reset = false;
  if (input.stamp < last_stamp_) {
    reset();
    was_reset = true;
  }
  // The segments move as the camera turns at its last rate; beyond that, by their own motion.
  Eigen::Matrix3d image_motion = Eigen::Matrix3d::Identity();
  if (keyframe_.valid && input.stamp > last_stamp_) {
    const Eigen::Vector3d w = angular_velocity_ * (input.stamp - last_stamp_);
    if (w.norm() > 0.0) {
      const Eigen::Matrix3d K = input.camera.pinhole.K();
      image_motion = K * Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() *
                     K.inverse();
    }
  }
  last_stamp_ = input.stamp;
  // Converted once: every stage takes this form.
  const GrayImage gray(input.image);
  StageTimings& times = r.stages;

  // The second thread's queue, in order: the stereo pair's pyramids, the segments, then its share
  // of the KLT searches and of the re-detection. This thread tracks the points meanwhile, then
  // estimates while the second one re-detects; both match the stereo points at the end.
  const bool tracking =
      !input.external.has_points && options_.point_source == PointFeatureSource::kTracking;
  const bool stereo = !input.right_image.empty() && input.baseline_m > 0.0;
  // The KLT tracker's pyramid of this image serves the stereo matching when its window and
  // levels suffice.
  const bool klt_pyramid = tracking && options_.klt.window_px >= options_.stereo.window_px &&
                           options_.klt.pyramid_levels >= options_.stereo.pyramid_levels;
  StereoPair pair;
  WorkerJob pyramids_job;
  if (stereo) {
    pair.camera = input.camera.pinhole;
    pair.baseline_m = input.baseline_m;
    pyramids_job = worker_->submit([&] {
      pair.right = stereo_pyramid(GrayImage(input.right_image).mat(), options_.stereo);
      if (!klt_pyramid) pair.left = stereo_pyramid(gray.mat(), options_.stereo);
    });
  }
  std::map<int64_t, Eigen::Vector2d> points;
  ImageFeatures features;
  std::vector<int64_t> line_ids;  // with track_lines: the track of each segment
  WorkerJob lines_job;
  if (options_.use_lines && !input.external.has_lines) {
    lines_job = worker_->submit([&] {
      const auto lines_start = std::chrono::steady_clock::now();
      features.lines = detect_line_features(gray, options_.features.lines);
      if (options_.track_lines)
        line_ids =
            line_tracker_.track(features.lines, input.stamp, &r.line_tracking, image_motion);
      times.lines_ms = ms_since(lines_start);
    });
  }
  const auto points_start = std::chrono::steady_clock::now();
  if (input.external.has_points) {
    for (size_t i = 0; i < input.external.points.size() && i < input.external.point_ids.size(); ++i)
      if (all_finite(input.external.points[i]))
        points[input.external.point_ids[i]] = input.external.points[i];
  } else if (tracking) {
    // The searches on both threads, the second once it has detected the segments.
    klt_.track_existing(gray, nullptr, input.stamp, worker_->parallel());
    points = klt_points();
    if (klt_pyramid) pair.left = klt_.pyramid();
  } else {
    features.points = detect_point_features(gray, options_.features.points);
    for (size_t i = 0; i < features.points.keypoints.size(); ++i)
      points[static_cast<int64_t>(i)] = Eigen::Vector2d(features.points.keypoints[i].pt.x,
                                                        features.points.keypoints[i].pt.y);
  }
  times.points_ms = ms_since(points_start);

  // Point matches keyframe -> current frame, and whether the frame moved enough to be estimated.
  TwoViewMatches& m = r.matches;
  std::vector<int64_t> point_ids;
  if (keyframe_.valid)
    match_points(points, features, !input.external.has_points && !tracking, &m, &point_ids);
  const double parallax = m.points.size() >= 5 ? median_motion_px(m.points) : -1.0;
  const bool low_parallax = parallax >= 0.0 && parallax < options_.min_parallax_px;

  // Stereo points of this frame's features, for the scale of this and the next motion: started
  // now, on the second thread while this one estimates, unless the frame is skipped (the few
  // whose estimate fails are cancelled). KLT tracking matches its tracks and, first, the
  // keyframe's new features tracked into this frame (Keyframe::stereo_pending); other points are
  // matched at once.
  const bool tracks = input.external.has_points || tracking;
  WorkClock stereo_clock;
  StereoFeatures current_stereo;
  SharedLoop stereo_loop;
  bool stereo_started = false;
  auto start_stereo = [&] {
    if (!stereo || stereo_started) return;
    stereo_started = true;
    pyramids_job.get();
    if (tracking) complete_keyframe_stereo(points, &stereo_clock);
    current_stereo = stereo_features(pair, points, tracks);
    StereoMatcher& matcher = *current_stereo.matcher;
    stereo_loop = worker_->share(matcher.chunks(),
                                 stereo_clock.timed([&matcher](int c) { matcher.search(c); }));
  };
  auto match_stereo = [&] {
    std::map<int64_t, Eigen::Vector3d> points3d;
    if (!stereo) return points3d;
    start_stereo();
    stereo_loop.join();
    times.stereo_ms = stereo_clock.ms();
    return current_stereo.points();
  };
  if (!keyframe_.valid || !low_parallax) start_stereo();

  // The re-detection serves only the next frame: cell by cell on the second thread while this
  // one estimates and fits the scale, and this one takes the cells left when it is done.
  // `points` holds the tracked features until then.
  KltDetection detection;
  SharedLoop redetection;
  WorkClock redetect_clock;
  if (tracking) {
    detection = klt_.plan_detection();
    redetection = worker_->share(detection.cells(), redetect_clock.timed([&](int cell) {
      klt_.detect_cell(&detection, cell);
    }));
  }
  auto finish_redetection = [&] {
    redetection.join();
    if (tracking) klt_.add_detections(detection);
    times.redetect_ms = redetect_clock.ms();
  };
  // The features that keyframe a frame: all the tracker holds once it has re-detected.
  auto keep_as_keyframe = [&](std::map<int64_t, Eigen::Vector3d> points3d) {
    finish_redetection();
    std::vector<int64_t> pending;
    if (tracking && stereo)
      for (const int64_t id : klt_.ids())
        if (!points.count(id)) pending.push_back(id);
    make_keyframe(input, gray.mat(), tracking ? klt_points() : points, std::move(points3d),
                  std::move(features), line_ids, std::move(pair), std::move(pending));
  };
  // A frame that is not kept: its stereo matching is left undone.
  auto skip_frame = [&] {
    stereo_loop.cancel();
    finish_redetection();
    r.total_ms = ms_since(start);
    return r;
  };
  lines_job.get();

  if (!keyframe_.valid) {
    keep_as_keyframe(match_stereo());
    r.status = was_reset ? VoStatus::kReset : VoStatus::kFirstFrame;
    r.message = was_reset ? "time went backwards: odometry reset" : "keyframe initialised";
    r.reference_stamp = input.stamp;
    r.frontend_ms = r.total_ms = ms_since(start);
    return r;
  }
  r.reference_stamp = keyframe_.stamp;

  // Segment matches keyframe -> current frame.
  if (input.external.has_lines) {
    for (size_t i = 0; i < input.external.lines.size() && i < input.external.line_ids.size(); ++i) {
      const auto it = keyframe_.external_lines.find(input.external.line_ids[i]);
      if (it != keyframe_.external_lines.end())
        m.lines.push_back({it->second, input.external.lines[i]});
    }
  } else if (options_.use_lines) {
    const auto matching_start = std::chrono::steady_clock::now();
    if (options_.track_lines) {
      for (size_t i = 0; i < line_ids.size(); ++i) {
        const auto it = keyframe_.tracked_lines.find(line_ids[i]);
        if (it != keyframe_.tracked_lines.end())
          m.lines.push_back({it->second, features.lines.segments[i]});
      }
    } else {
      m.lines = match_line_features(keyframe_.features.lines, features.lines,
                                    options_.features.lines);
    }
    times.line_matching_ms = ms_since(matching_start);
  }
  r.num_point_matches = static_cast<int>(m.points.size());
  r.num_line_matches = static_cast<int>(m.lines.size());
  r.frontend_ms = ms_since(start);

  if (r.num_point_matches < options_.min_point_matches &&
      r.num_line_matches < options_.min_line_matches) {
    keep_as_keyframe(match_stereo());
    r.status = VoStatus::kTooFewFeatures;
    r.message = "too few matches (" + std::to_string(r.num_point_matches) + " points, " +
                std::to_string(r.num_line_matches) + " segments): re-initialised";
    r.total_ms = ms_since(start);
    return r;
  }
  if (low_parallax) {
    r.status = VoStatus::kLowParallax;
    r.message = "median motion " + std::to_string(parallax) + " px";
    return skip_frame();
  }

  // Estimation: VPs detected jointly, refined by the tracker, then the hybrid RANSAC.
  const auto estimate_start = std::chrono::steady_clock::now();
  // Undistort what is still distorted (external features may come undistorted already).
  const bool points_done = input.external.has_points && input.external.points_undistorted &&
                           keyframe_.points_undistorted;
  const bool lines_done = input.external.has_lines && input.external.lines_undistorted &&
                          keyframe_.lines_undistorted;
  {
    TwoViewMatches distorted;
    if (!points_done) std::swap(distorted.points, m.points);
    if (!lines_done) std::swap(distorted.lines, m.lines);
    undistort_matches(keyframe_.camera, input.camera, &distorted);
    if (!points_done) std::swap(distorted.points, m.points);
    if (!lines_done) std::swap(distorted.lines, m.lines);
  }
  TwoViewOptions estimator = options_.estimator;
  const auto vps_start = std::chrono::steady_clock::now();
  if (uses_vps(estimator) && !m.lines.empty()) {
    VpDetectionOptions vp_options = estimator.vp_detection;
    const MatchedVps vps = estimator.joint_vp_detection
                               ? detect_vanishing_points_joint(keyframe_.camera.pinhole,
                                                               input.camera.pinhole, m.lines,
                                                               vp_options)
                               : detect_vanishing_points_standard(keyframe_.camera.pinhole,
                                                                  input.camera.pinhole, m.lines,
                                                                  vp_options);
    m.vps = vps.matches;
    m.line_vp = vps.labels;
    if (options_.use_vp_tracker) {
      if (!tracker_seeded_) {
        vp_tracker_.update(keyframe_.R_wc,
                           vp_observations(keyframe_.camera.pinhole.K(), m, false,
                                           options_.estimator.vp_detection.inlier_threshold_px /
                                               3.0,
                                           options_.estimator.ransac.vp_threshold_deg /
                                               3.0));
        tracker_seeded_ = true;
      }
      m.vp_priors = vp_tracker_.priors(keyframe_.R_wc, m.vps);
      for (const VpPrior& prior : m.vp_priors) r.vp_track_ids.push_back(prior.track_id);
    }
  }
  times.vps_ms = ms_since(vps_start);
  estimator.detect_vps = false;  // detected above (or unwanted)
  const auto ransac_start = std::chrono::steady_clock::now();
  r.estimate = estimate_two_view(keyframe_.camera.pinhole, input.camera.pinhole, m, estimator);
  times.ransac_ms = ms_since(ransac_start);
  r.estimate.vps.matches = m.vps;
  r.estimate.vps.labels = m.line_vp;
  r.estimator_ms = ms_since(estimate_start);
  const RelativePoseEstimate& est = r.estimate.estimate;
  if (est.status != EstimationStatus::kOk) {
    r.status = VoStatus::kNoPose;
    r.message = std::string("estimator: ") + hybrid_vo::to_string(est.status);
    return skip_frame();
  }

  // Orientation: the pair's rotation, anchored by the VP tracks it sees (VpTracker::anchor).
  // The scale's observations, their current points refined on this thread while the second one
  // still matches the stereo points (then it re-detects while this one fits the scale); then
  // this frame's disparities.
  std::vector<StereoScaleObservation> observations;
  std::vector<int64_t> observed;
  const auto refine_start = std::chrono::steady_clock::now();
  if (stereo)
    observations = scale_observations(input, gray.mat(), m, point_ids, est.point_inliers,
                                      points, tracking, &observed);
  times.scale_ms = ms_since(refine_start);
  std::map<int64_t, Eigen::Vector3d> current3d = match_stereo();
  if (stereo) add_current_disparities(input, observed, current3d, &observations);
  RelativePose pose = est.pose;
  std::vector<VpObservation> seen;  // the VPs the pose accepts, as seen in image 2
  if (options_.use_vp_tracker) {
    // Each with the covariance of its fit to image 2's segments at the pair's measured segment
    // noise.
    TwoViewMatches inliers;
    inliers.lines = m.lines;
    inliers.line_vp = m.line_vp;
    std::vector<int> kept(m.vps.size(), -1);
    for (size_t k = 0; k < m.vps.size(); ++k) {
      if (k < est.vp_inliers.size() && !est.vp_inliers[k]) continue;
      kept[k] = static_cast<int>(inliers.vps.size());
      inliers.vps.push_back(m.vps[k]);
    }
    for (int& label : inliers.line_vp) label = label >= 0 ? kept[label] : -1;
    seen = vp_observations(input.camera.pinhole.K(), inliers, true, est.scales.line_vp_px,
                           est.scales.vp_deg);
  }
  Eigen::Matrix3d R_wc = nearest_rotation(keyframe_.R_wc * pose.R.transpose());
  {
    // The pair's rotation error as a left increment of R (camera 2) is -R_wc times it in the
    // odometry frame.
    const double floor = options_.rotation_drift_floor_deg * M_PI / 180.0;
    R_wc_covariance_ = keyframe_.R_wc_covariance + floor * floor * Eigen::Matrix3d::Identity();
    if (est.covariance_valid)
      R_wc_covariance_ += R_wc * est.covariance.topLeftCorner<3, 3>() * R_wc.transpose();
  }
  if (options_.use_vp_tracker && options_.anchor_orientation) {
    r.anchoring = vp_tracker_.anchor(R_wc, R_wc_covariance_, seen);
    R_wc_covariance_ = r.anchoring.covariance;
    // The correction is the drift of earlier pairs, not this pair's motion: the translation
    // stays as this pair's points fixed it (re-fitted under the anchored rotation, it was 37 ->
    // 51 deg off on TUM fr3 structure_notexture).
    if (r.anchoring.anchors > 0) {
      R_wc = r.anchoring.R_world_from_camera;
      pose.R = nearest_rotation(R_wc.transpose() * keyframe_.R_wc);
    }
  }

  // Scale: the keyframe's stereo points seen again, with this frame's disparities, fitted in
  // disparity and image space (estimate_stereo_scale); without a usable fit, the configured
  // length and scale_known false.
  r.motion = pose;
  double scale = options_.mono_scale, scale_sigma = 0.0;
  if (stereo) {
    r.stereo_scale_attempted = true;
    const auto scale_start = std::chrono::steady_clock::now();
    r.scale_observations = std::move(observations);
    const StereoRig rig{input.camera.pinhole.fx, input.camera.pinhole.fy, input.baseline_m};
    // The pair's own pose: its rotation and translation explain its points together, and the
    // scale is fitted to those points (with the anchored rotation the demo's ATE was 0.0135 m
    // against 0.0115).
    offset_filter_.update(est.pose, rig, r.scale_observations, options_.stereo_scale);
    StereoScaleOptions scale_options = options_.stereo_scale;
    scale_options.disparity_offset_px = r.disparity_offset_px = offset_filter_.offset();
    r.stereo_scale = estimate_stereo_scale(est.pose, rig, r.scale_observations, scale_options);
    if (r.stereo_scale.status == StereoScaleStatus::kOk) {
      scale = r.stereo_scale.scale;
      scale_sigma = r.stereo_scale.sigma;
      r.scale_known = true;
    }
    times.scale_ms += ms_since(scale_start);
  }
  r.motion.t = pose.t * scale;
  if (est.covariance_valid) {
    r.motion_covariance = metric_motion_covariance(est.covariance, pose.t, scale, scale_sigma);
    r.motion_covariance_valid = true;
  }

  if (input.stamp > keyframe_.stamp) {
    const Eigen::AngleAxisd turned(est.pose.R);
    angular_velocity_ = turned.angle() * turned.axis() / (input.stamp - keyframe_.stamp);
  }

  // Integrate: the current camera's centre in the keyframe is -R^T t.
  R_wc_ = R_wc;
  centre_ = keyframe_.centre - keyframe_.R_wc * r.motion.R.transpose() * r.motion.t;
  r.R_wc = R_wc_;
  r.centre = centre_;
  // Every estimated frame, also without VPs, so that misses count.
  if (options_.use_vp_tracker) r.vp_associations = vp_tracker_.update(R_wc_, seen);
  keep_as_keyframe(std::move(current3d));
  r.status = VoStatus::kOk;
  r.message = "ok";
  r.total_ms = ms_since(start);
  return r;
}

}  // namespace hybrid_vo
