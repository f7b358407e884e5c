// The video front end on a rendered sequence: the threaded front end gives exactly the matches
// and poses of the sequential one, colour frames those of grey ones, segment tracking is as correct as full LBD matching without
// using any point, the stereo scale's current points do not lag on approaching
// surfaces, the KLT tracker split over threads tracks as the sequential one, and the worker
// thread and the tracker behave at their edges.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <functional>
#include <future>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/estimation/relative_pose_estimator.h"
#include "hybrid_vo/features/klt_tracker.h"
#include "hybrid_vo/features/line_tracker.h"
#include "hybrid_vo/features/worker_thread.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose_covariance.h"
#include "hybrid_vo/odometry/visual_odometry.h"
#include "hybrid_vo/render/renderer.h"
#include "hybrid_vo/render/sequence.h"
#include "image_test_utils.h"

namespace {

using namespace hybrid_vo;
using namespace hybrid_vo::render;

constexpr int kFrames = 14;

// A short rendered stereo corridor, shared by the tests (rendering dominates their time).
class VideoFrontEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SequenceOptions options;
    options.out_bag = "unused.bag";
    options.frames = kFrames;
    options.stereo = true;
    options.supersampling = 1;
    sequence_ = new Sequence(make_sequence(options));
    left_ = new std::vector<RenderedView>();
    right_ = new std::vector<cv::Mat>();
    for (int i = 0; i < kFrames; ++i) {
      left_->push_back(render_frame(*sequence_, i));
      right_->push_back(render_frame(*sequence_, i, true).image);
    }
  }
  static void TearDownTestSuite() {
    delete sequence_;
    delete left_;
    delete right_;
  }

  static VisualOdometryInput input(int i, bool stereo) {
    VisualOdometryInput in;
    in.stamp = 1.0 + i / sequence_->options.rate;
    in.image = (*left_)[i].image;
    in.camera.pinhole = sequence_->camera;
    if (stereo) {
      in.right_image = (*right_)[i];
      in.baseline_m = sequence_->options.baseline;
    }
    return in;
  }

  static Sequence* sequence_;
  static std::vector<RenderedView>* left_;
  static std::vector<cv::Mat>* right_;
};

Sequence* VideoFrontEnd::sequence_ = nullptr;
std::vector<RenderedView>* VideoFrontEnd::left_ = nullptr;
std::vector<cv::Mat>* VideoFrontEnd::right_ = nullptr;

bool same_points(const std::vector<PointMatch>& a, const std::vector<PointMatch>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k)
    if (a[k].x1 != b[k].x1 || a[k].x2 != b[k].x2) return false;
  return true;
}

bool same_lines(const std::vector<LineMatch>& a, const std::vector<LineMatch>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k)
    if (a[k].s1.p1 != b[k].s1.p1 || a[k].s1.p2 != b[k].s1.p2 || a[k].s2.p1 != b[k].s2.p1 ||
        a[k].s2.p2 != b[k].s2.p2)
      return false;
  return true;
}

// Runs `inputs_a` through `a` and `inputs_b` through `b` and compares frame by frame: the same
// statuses, matches, map directions, motions and poses, digit for digit.
void expect_same_odometry(VisualOdometry& a, const std::vector<VisualOdometryInput>& inputs_a,
                          VisualOdometry& b, const std::vector<VisualOdometryInput>& inputs_b) {
  ASSERT_EQ(inputs_a.size(), inputs_b.size());
  int estimated = 0, with_lines = 0;
  for (size_t i = 0; i < inputs_a.size(); ++i) {
    const VisualOdometryResult ra = a.process(inputs_a[i]);
    const VisualOdometryResult rb = b.process(inputs_b[i]);
    ASSERT_EQ(ra.status, rb.status) << "frame " << i;
    EXPECT_TRUE(same_points(ra.matches.points, rb.matches.points)) << "frame " << i;
    EXPECT_TRUE(same_lines(ra.matches.lines, rb.matches.lines)) << "frame " << i;
    EXPECT_EQ(ra.num_line_matches, rb.num_line_matches) << "frame " << i;
    EXPECT_EQ(ra.vp_track_ids, rb.vp_track_ids) << "frame " << i;
    EXPECT_EQ(ra.orientation.source, rb.orientation.source) << "frame " << i;
    EXPECT_EQ(ra.orientation.location.direction_id, rb.orientation.location.direction_id)
        << "frame " << i;
    EXPECT_EQ(ra.motion.R, rb.motion.R) << "frame " << i;
    EXPECT_EQ(ra.motion.t, rb.motion.t) << "frame " << i;
    EXPECT_EQ(ra.R_wc, rb.R_wc) << "frame " << i;
    EXPECT_EQ(ra.centre, rb.centre) << "frame " << i;
    EXPECT_EQ(ra.pose_covariance, rb.pose_covariance) << "frame " << i;
    EXPECT_EQ(ra.scale_known, rb.scale_known) << "frame " << i;
    EXPECT_EQ(ra.scale_observations.size(), rb.scale_observations.size()) << "frame " << i;
    estimated += ra.status == VoStatus::kOk;
    with_lines += ra.num_line_matches >= 20;
  }
  // The comparison means something only when frames were estimated with many segments.
  EXPECT_GE(estimated, static_cast<int>(inputs_a.size()) / 2);
  EXPECT_GE(with_lines, static_cast<int>(inputs_a.size()) / 2);
}

// Runs the whole sequence twice, threaded and sequential, and compares frame by frame.
void expect_threaded_equals_sequential(const std::vector<VisualOdometryInput>& inputs,
                                       const VisualOdometryOptions& options) {
  VisualOdometryOptions threaded = options, sequential = options;
  threaded.concurrent = true;
  sequential.concurrent = false;
  VisualOdometry a(threaded), b(sequential);
  expect_same_odometry(a, inputs, b, inputs);
}

TEST_F(VideoFrontEnd, ThreadedFrontEndGivesTheSequentialMatchesAndPoses) {
  std::vector<VisualOdometryInput> mono, stereo;
  for (int i = 0; i < kFrames; ++i) {
    mono.push_back(input(i, false));
    stereo.push_back(input(i, true));
  }
  VisualOdometryOptions lbd, descriptors;
  lbd.track_lines = false;
  descriptors.point_source = PointFeatureSource::kDescriptors;
  expect_threaded_equals_sequential(mono, VisualOdometryOptions());
  expect_threaded_equals_sequential(mono, lbd);
  expect_threaded_equals_sequential(stereo, VisualOdometryOptions());
  expect_threaded_equals_sequential(stereo, descriptors);
}

// The lightest fixed work level (cpu_budget.h): half the point budget, no segment descriptors, so
// no re-identification and no candidate told apart by one, and yet the corridor's motion.
TEST_F(VideoFrontEnd, TheLightestWorkLevelDoesLessAndStillFollowsTheCorridor) {
  auto run = [](int level, std::vector<VisualOdometryResult>* results) {
    VisualOdometryOptions options;
    options.features.points.max_features = 400;
    options.budget.min_work_level = level;
    VisualOdometry vo(options);
    for (int i = 0; i < kFrames; ++i) results->push_back(vo.process(input(i, false)));
  };
  std::vector<VisualOdometryResult> full, light;
  run(0, &full);
  run(kMaxWorkLevel, &light);
  const CameraPose first = frame_pose(*sequence_, 0);
  int estimated = 0, most_points_full = 0, most_points_light = 0;
  for (int i = 0; i < kFrames; ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    EXPECT_EQ(full[i].work_level, 0);
    EXPECT_EQ(light[i].work_level, kMaxWorkLevel);
    EXPECT_EQ(light[i].line_tracking.reidentified, 0);
    EXPECT_EQ(light[i].line_tracking.ambiguous, 0);
    EXPECT_LE(light[i].num_point_matches, 200);
    most_points_full = std::max(most_points_full, full[i].num_point_matches);
    most_points_light = std::max(most_points_light, light[i].num_point_matches);
    if (light[i].status != VoStatus::kOk) continue;
    ++estimated;
    const Eigen::Matrix3d truth = first.R_world_from_camera.transpose() *
                                  frame_pose(*sequence_, i).R_world_from_camera;
    EXPECT_LT(Eigen::AngleAxisd(light[i].R_wc.transpose() * truth).angle() * 180.0 / M_PI, 0.5);
  }
  EXPECT_GT(most_points_full, 200);  // the full level used the whole budget, the light one half
  EXPECT_GT(most_points_light, 100);
  EXPECT_GE(estimated, kFrames / 2);
}

// A colour camera's frames are converted to grey once, where they come in: BGR copies of the
// grey frames (which cv::cvtColor turns back into the grey ones exactly) give their odometry.
TEST_F(VideoFrontEnd, ColourFramesGiveTheGreyFramesOdometry) {
  std::vector<VisualOdometryInput> grey, colour;
  for (int i = 0; i < kFrames; ++i) {
    grey.push_back(input(i, true));
    VisualOdometryInput in = grey.back();
    cv::cvtColor(grey.back().image, in.image, cv::COLOR_GRAY2BGR);
    cv::cvtColor(grey.back().right_image, in.right_image, cv::COLOR_GRAY2BGR);
    colour.push_back(in);
  }
  VisualOdometry a, b;
  expect_same_odometry(a, colour, b, grey);
}

// The pose's covariance (geometry/pose_covariance.h has its maths against Monte-Carlo): a
// covariance in every frame, the orientation block at least the map's, the position growing along
// the chain and in mono in units of mono_scale; a restart keeps it with the pose, a reset (or time
// going backwards) zeroes it with the pose.
TEST_F(VideoFrontEnd, PoseCovarianceAccumulatesAndFollowsThePose) {
  auto position = [](const VisualOdometryResult& r) {
    return r.pose_covariance.topLeftCorner<3, 3>().trace();
  };
  VisualOdometry vo;
  VisualOdometryResult r;
  double first_position = 0.0;
  int estimated = 0, without_covariance = 0;
  for (int i = 0; i < kFrames; ++i) {
    r = vo.process(input(i, true));
    SCOPED_TRACE("frame " + std::to_string(i));
    EXPECT_TRUE(is_covariance(r.pose_covariance));
    if (i == 0) {
      EXPECT_EQ(r.pose_covariance, Matrix6d::Zero());  // the origin is exact
    }
    if (r.status != VoStatus::kOk) continue;
    ++estimated;
    without_covariance += !r.motion_covariance_valid;
    // At least the map's: the reported one bounds the pairs' correlated errors beside it.
    const Eigen::Matrix3d beyond =
        r.pose_covariance.bottomRightCorner<3, 3>() - r.orientation.covariance;
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(0.5 * (beyond + beyond.transpose()))
                  .eigenvalues()
                  .minCoeff(),
              -1e-12 * r.orientation.covariance.norm());
    EXPECT_GT(position(r), 0.0);
    if (first_position == 0.0) first_position = position(r);
  }
  EXPECT_GE(estimated, kFrames / 2);
  EXPECT_EQ(r.pose_covariance_gaps, without_covariance);
  EXPECT_GT(position(r), 2.0 * first_position);

  // A restart keeps the pose and its covariance; a reset returns both to the exact origin, and
  // so does time going backwards.
  const VisualOdometryResult before = r;
  vo.restart();
  r = vo.process(input(kFrames - 1, true));
  EXPECT_EQ(r.status, VoStatus::kFirstFrame);
  EXPECT_EQ(r.centre, before.centre);
  EXPECT_EQ(r.pose_covariance, before.pose_covariance);
  vo.reset();
  r = vo.process(input(0, true));
  EXPECT_EQ(r.pose_covariance, Matrix6d::Zero());
  r = vo.process(input(1, true));
  ASSERT_EQ(r.status, VoStatus::kOk);
  EXPECT_GT(position(r), 0.0);
  r = vo.process(input(0, true));
  EXPECT_EQ(r.status, VoStatus::kReset);
  EXPECT_EQ(r.centre, Eigen::Vector3d::Zero());
  EXPECT_EQ(r.pose_covariance, Matrix6d::Zero());

  // Mono: the same poses at twice the mono_scale have twice the position's standard deviation.
  VisualOdometryOptions doubled;
  doubled.mono_scale = 2.0;
  VisualOdometry unit_vo, doubled_vo(doubled);
  int compared = 0;
  for (int i = 0; i < kFrames; ++i) {
    const VisualOdometryResult a = unit_vo.process(input(i, false));
    const VisualOdometryResult b = doubled_vo.process(input(i, false));
    ASSERT_EQ(a.status, b.status);
    if (a.status != VoStatus::kOk) continue;
    ++compared;
    EXPECT_NEAR(position(b), 4.0 * position(a), 1e-6 * position(b)) << "frame " << i;
    EXPECT_LT((a.pose_covariance.bottomRightCorner<3, 3>() -
               b.pose_covariance.bottomRightCorner<3, 3>()).norm(),
              1e-9 * a.pose_covariance.norm());
  }
  EXPECT_GE(compared, kFrames / 2);
}

// Distance in pixels from the rendered ground truth: a keyframe segment's endpoints carried into
// the current view by their depth, against the matched segment's line.
double line_error_px(const RenderedView& view1, const CameraPose& pose1, const CameraPose& pose2,
                     const PinholeCamera& cam, const LineMatch& m) {
  double worst = 0.0;
  const Eigen::Vector3d l2 = line_through(m.s2.p1, m.s2.p2);
  for (double t : {0.1, 0.9}) {
    // Inside the segment: its endpoints sit on the depth edge that makes it.
    const Eigen::Vector2d p = m.s1.p1 + t * (m.s1.p2 - m.s1.p1);
    const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
    if (x < 0 || y < 0 || x >= view1.depth.cols || y >= view1.depth.rows) return -1.0;
    const float z = view1.depth.at<float>(y, x);
    if (!(z > 0.0f)) return -1.0;
    const Eigen::Vector3d ray((p.x() - cam.cx) / cam.fx, (p.y() - cam.cy) / cam.fy, 1.0);
    const Eigen::Vector3d X = pose1.to_world(ray * z);
    const Eigen::Vector3d Xc = pose2.to_camera(X);
    if (Xc.z() <= 0.0) return -1.0;
    const Eigen::Vector2d q(cam.fx * Xc.x() / Xc.z() + cam.cx, cam.fy * Xc.y() / Xc.z() + cam.cy);
    worst = std::max(worst, std::abs(l2.dot(homogeneous(q))));
  }
  return worst;
}

TEST_F(VideoFrontEnd, SegmentTracksAreAsCorrectAsLbdMatchingWithoutAnyPoint) {
  const PinholeCamera& cam = sequence_->camera;
  const LineMatchingOptions matching = video_line_matching_options();
  LineTracker tracker;
  int lbd_total = 0, lbd_wrong = 0, tracked_total = 0, tracked_wrong = 0;
  LineFeatures previous = detect_line_features((*left_)[0].image, matching);
  std::vector<int64_t> previous_ids = tracker.track(previous, input(0, false).stamp);
  for (int i = 1; i < kFrames; ++i) {
    const LineFeatures current = detect_line_features((*left_)[i].image, matching);
    LineTrackingStats stats;
    const std::vector<int64_t> ids = tracker.track(current, input(i, false).stamp, &stats);
    ASSERT_EQ(ids.size(), current.segments.size());
    EXPECT_EQ(stats.matched + stats.started, static_cast<int>(current.segments.size()));
    EXPECT_LE(stats.ambiguous, stats.matched);
    std::vector<LineMatch> by_id;
    for (size_t j = 0; j < ids.size(); ++j)
      for (size_t k = 0; k < previous_ids.size(); ++k)
        if (previous_ids[k] == ids[j]) by_id.push_back({previous.segments[k], current.segments[j]});
    const std::vector<LineMatch>& tracked = by_id;
    const std::vector<LineMatch> lbd = match_line_features(previous, current, matching);
    const CameraPose pose1 = frame_pose(*sequence_, i - 1), pose2 = frame_pose(*sequence_, i);
    for (const auto& [matches, total, wrong] :
         {std::tie(tracked, tracked_total, tracked_wrong), std::tie(lbd, lbd_total, lbd_wrong)}) {
      for (const LineMatch& m : matches) {
        const double e = line_error_px((*left_)[i - 1], pose1, pose2, cam, m);
        if (e < 0.0) continue;  // no depth under it
        ++total;
        wrong += e > 3.0;
      }
    }
    previous = current;
    previous_ids = ids;
  }
  ASSERT_GT(lbd_total, 100);
  // Ids link most segments of consecutive frames, as many as LBD matches or nearly.
  EXPECT_GE(tracked_total, 0.8 * lbd_total) << tracked_total << " vs " << lbd_total;
  // Precision no worse than LBD's (one wrong match of slack on ~100s of matches).
  EXPECT_LE(static_cast<double>(tracked_wrong) / tracked_total,
            static_cast<double>(lbd_wrong + 1) / lbd_total)
      << tracked_wrong << " of " << tracked_total << " vs " << lbd_wrong << " of " << lbd_total;
}

// The stereo scale's near points (closer than 40 baselines) in the current image, against the
// scene: each keyframe ray's hit carried into the current frame. Their error along the true
// flow (pixels; negative: short of where the point went), where the flow is over 3 px and the
// point's window lies on one surface; errors beyond 1 px (lost tracks, which the fit's robust
// loss discounts) left out. Also the scale fitted with the true motion and disparities and
// these current points, over the true length, per pair.
struct ScalePointErrors {
  std::vector<double> along, scale_ratio;
};

double mean_of(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return v.empty() ? NAN : sum / v.size();
}

ScalePointErrors scale_point_errors(const Sequence& seq,
                                    const std::function<VisualOdometryInput(int)>& input,
                                    const VisualOdometryOptions& options) {
  VisualOdometry vo(options);
  const PinholeCamera& cam = seq.camera;
  const double fb = cam.fx * seq.options.baseline;
  ScalePointErrors errors;
  for (int i = 0; i < kFrames; ++i) {
    const VisualOdometryResult r = vo.process(input(i));
    if (r.status != VoStatus::kOk) continue;
    const int ref = static_cast<int>(std::lround((r.reference_stamp - 1.0) * seq.options.rate));
    const CameraPose a = frame_pose(seq, ref), b = frame_pose(seq, i);
    const Eigen::Matrix3d R = b.R_world_from_camera.transpose() * a.R_world_from_camera;
    std::vector<StereoScaleObservation> truth;
    for (const StereoScaleObservation& o : r.scale_observations) {
      if (o.disparity_ref < cam.fx / 40.0) continue;
      double z = 0.0;
      const int quad =
          cast_ray(seq.scene, a.centre, a.R_world_from_camera * homogeneous(o.x_ref), &z);
      bool one_surface = quad >= 0;
      for (const double dx : {-7.0, 7.0})
        for (const double dy : {-7.0, 7.0}) {
          const Eigen::Vector2d x = o.x_ref + Eigen::Vector2d(dx / cam.fx, dy / cam.fy);
          double zn = 0.0;
          one_surface &=
              cast_ray(seq.scene, a.centre, a.R_world_from_camera * homogeneous(x), &zn) == quad;
        }
      if (!one_surface) continue;
      const Eigen::Vector3d X = b.to_camera(a.to_world(z * homogeneous(o.x_ref)));
      StereoScaleObservation t = o;
      t.x_cur = X.head<2>() / X.z();
      t.disparity_ref = fb / z;
      if (t.disparity_cur > 0.0) t.disparity_cur = fb / X.z();
      const Eigen::Vector3d rotated = R * homogeneous(o.x_ref);
      const Eigen::Vector2d flow = cam.fx * (t.x_cur - rotated.head<2>() / rotated.z());
      const double along = cam.fx * (o.x_cur - t.x_cur).dot(flow.normalized());
      if (flow.norm() > 3.0 && std::abs(along) < 1.0) errors.along.push_back(along);
      truth.push_back(t);
      truth.back().x_cur = o.x_cur;  // the point as measured
    }
    const Eigen::Vector3d t = b.to_camera(a.centre);
    const StereoRig rig{cam.fx, cam.fy, seq.options.baseline};
    const StereoScaleEstimate e =
        estimate_stereo_scale(RelativePose(R, t.normalized()), rig, truth, options.stereo_scale);
    if (e.status == StereoScaleStatus::kOk) errors.scale_ratio.push_back(e.scale / t.norm());
  }
  return errors;
}

// Issue 17: the corridor's scale was 0.15 % short per pair. The cause was the KLT tracker's
// current points: its translated window lags along the flow on surfaces that come closer,
// where the pose's epipolar test cannot see it. Affine refinement removes the lag.
TEST_F(VideoFrontEnd, StereoScalePointsDoNotLagOnApproachingSurfaces) {
  auto in = [](int i) { return input(i, true); };
  // Every corner the detector finds, weak ones too: those lag the most (with the default
  // klt.min_corner_gradient half of them are not tracked, and the lag is -0.009 px, refined
  // -0.005).
  VisualOdometryOptions defaults;
  defaults.klt.min_corner_gradient = 0.0;
  defaults.klt.strongest_first = false;  // which would leave the weak ones for last
  VisualOdometryOptions klt_points = defaults;
  klt_points.stereo_refine_tracks = false;
  klt_points.stereo_scale.point_sigma_px = 0.5;  // the weight the KLT's points had
  const ScalePointErrors tracked = scale_point_errors(*sequence_, in, klt_points);
  const ScalePointErrors refined = scale_point_errors(*sequence_, in, defaults);
  ASSERT_GT(tracked.along.size(), 1000u);
  ASSERT_GT(refined.along.size(), 1000u);
  std::vector<double> a = tracked.scale_ratio, b = refined.scale_ratio;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  std::printf("along the flow: tracked %+.4f px (%zu), refined %+.4f px (%zu); scale from the "
              "current points: tracked %.4f, refined %.4f (median of %zu pairs)\n",
              mean_of(tracked.along), tracked.along.size(), mean_of(refined.along),
              refined.along.size(), a[a.size() / 2], b[b.size() / 2], b.size());
  ASSERT_GE(b.size(), 10u);
  // The cause, with the tracker's points (the scale before): they lag, the scale is short.
  EXPECT_LT(mean_of(tracked.along), -0.006);
  EXPECT_LT(a[a.size() / 2], 0.9985);
  // The default (refined): under a third of the lag (KLT window 11 px: -0.014 -> -0.004 px; 21
  // px: -0.011 -> +0.001), and the scale from the current points is within 0.15 % of the truth.
  EXPECT_LT(std::abs(mean_of(refined.along)), 0.006);
  EXPECT_LT(std::abs(mean_of(refined.along)), std::abs(mean_of(tracked.along)) / 3.0);
  EXPECT_NEAR(b[b.size() / 2], 1.0, 0.0015);
}

// A camera panning at a constant image velocity, one frame lost: with stamps the tracker predicts
// the gap's motion (two steps), without them one step, and the one-level search from there
// misses. Textured noise, shifted by whole pixels, so that the truth is exact.
TEST(KltTracker, StampsCarryThePredictionOverADroppedFrame) {
  const cv::Mat texture = hybrid_vo::testing::blurred_noise(700, 1000, 2.5);
  const int step_px = 14;  // image motion per frame
  auto frame = [&](int k) { return texture(cv::Rect(200 - k * step_px, 100, 640, 480)).clone(); };
  // Frames 0, 1, 2 at 10 Hz, then frame 4 (frame 3 lost).
  auto track_with_gap = [&](bool stamps, int* correct) {
    KltTracker klt;
    std::vector<PointMatch> matches;
    for (const int k : {0, 1, 2, 4}) {
      const double stamp = stamps ? 0.1 * k : KltTracker::kNoStamp;
      matches = klt.track(frame(k), nullptr, stamp);
    }
    *correct = 0;
    for (const PointMatch& m : matches)
      *correct += (m.x2 - m.x1 - Eigen::Vector2d(2.0 * step_px, 0.0)).norm() < 0.5;
    return static_cast<int>(matches.size());
  };
  int correct_with = 0, correct_without = 0;
  const int with = track_with_gap(true, &correct_with);
  const int without = track_with_gap(false, &correct_without);
  ASSERT_GT(with, 200);
  EXPECT_GE(correct_with, 0.98 * with) << with;
  // One step short is beyond the short search's reach for most features; what the long search
  // recovers is not enough.
  EXPECT_GT(correct_with, correct_without + with / 10) << correct_without << " of " << without;
}

// Runs the indices of a ParallelFor backwards: whatever order the threads take them in, each
// index writes only its own results.
void backwards(int n, const std::function<void(int)>& body) {
  for (int i = n - 1; i >= 0; --i) body(i);
}

bool same_tracker(const KltTracker& a, const KltTracker& b) {
  return a.ids() == b.ids() && a.points() == b.points();
}

// Issue 32: the searches and the re-detection's cells split over threads (here: backwards, and
// on a worker thread beside this one) give the tracks of the sequential tracker, also when
// max_features leaves less room than the empty cells want.
// redetect_alternate (the CPU budget's first level): after the first frame, which fills every
// cell, each re-detection looks in one colour of a checkerboard of the grid's cells, the other
// colour the next time; and a reset starts with every cell again.
// Long straight bands on the left (edges without a corner: a point on them slides along), small
// squares on the right (corners). Every corner passes the isotropy test; of the points on the
// bands, goodFeaturesToTrack admits many where nothing stronger is near, the test none.
TEST(KltTracker, IsotropyLeavesOutPointsOnStraightEdges) {
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(40));
  const Eigen::Vector2d along = Eigen::Vector2d(200.0, 580.0).normalized();
  std::vector<Eigen::Vector2d> starts;
  for (int k = 0; k < 6; ++k) {
    starts.emplace_back(-150.0 + 45.0 * k, -50.0);
    const Eigen::Vector2d end = starts.back() + 620.0 * along;
    cv::line(image, cv::Point(starts.back().x(), starts.back().y()), cv::Point(end.x(), end.y()),
             cv::Scalar(200), 3, cv::LINE_AA);
  }
  for (int y = 40; y < 440; y += 50)
    for (int x = 400; x < 620; x += 50)
      cv::rectangle(image, cv::Rect(x, y, 18, 18), cv::Scalar(190), cv::FILLED);
  cv::Mat noise(image.size(), CV_8UC1);
  cv::randn(noise, 0, 2);
  image += noise;
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  auto on_a_band = [&](const cv::Point2f& p) {
    for (const Eigen::Vector2d& a : starts) {
      const Eigen::Vector2d q = Eigen::Vector2d(p.x, p.y) - a;
      if (std::abs(q.x() * along.y() - q.y() * along.x()) < 5.0) return true;
    }
    return false;
  };
  // The weak-corner rule left out (weak_corner_gradient 0): it too keeps edges out while there
  // are corners enough, and would hide what the isotropy does.
  auto count = [&](double isotropy, int* corners, double weak_gradient = 0.0) {
    KltTrackerOptions options;
    options.min_corner_isotropy = isotropy;
    options.weak_corner_gradient = weak_gradient;
    KltTracker tracker(options, 600);
    tracker.track(image);
    int edge = 0;
    *corners = 0;
    for (const cv::Point2f& p : tracker.points()) {
      edge += on_a_band(p) && p.x < 380.0f;
      *corners += p.x > 390.0f;
    }
    return edge;
  };
  int corners_all = 0, corners_isotropic = 0;
  const int edge_all = count(0.0, &corners_all);
  const int edge_isotropic = count(0.3, &corners_isotropic);
  EXPECT_GT(edge_all, 20);
  EXPECT_EQ(edge_isotropic, 0);
  EXPECT_GE(corners_isotropic, corners_all * 9 / 10);
  EXPECT_GT(corners_isotropic, 60);  // four corners of most of the 40 squares
  // The default's weak-corner rule: an edge's weaker gradient is noise, so its points wait until
  // the tracker runs short of corners, which 160 corners spare it here.
  int corners_default = 0;
  EXPECT_LE(count(0.0, &corners_default, KltTrackerOptions().weak_corner_gradient), edge_all / 4);
  EXPECT_GE(corners_default, corners_all * 9 / 10);
}

// refill_below: a pan over a texture with fewer good corners than max_features. While most of
// what the last re-detection left is still tracked no cell looks for corners; once a fifth of it
// has left the view, every empty cell does.
TEST(KltTracker, RefillWaitsUntilAShareOfTheLastRefillIsLost) {
  const cv::Mat texture = hybrid_vo::testing::blurred_noise(700, 1400, 2.5);
  auto frame = [&](double shift) {
    const cv::Matx23d warp(1, 0, -150 + shift, 0, 1, -100);
    cv::Mat image;
    cv::warpAffine(texture, image, warp, cv::Size(640, 480),
                   cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    return image;
  };
  KltTrackerOptions options;
  options.refill_below = 0.8;
  KltTracker tracker(options, 3000);  // more than the texture's corners: the cap is never met
  tracker.track(frame(0.0), nullptr, 0.0);
  const int filled = tracker.num_tracks();
  ASSERT_GT(filled, 200);
  ASSERT_LT(filled, 0.8 * 3000);
  auto wanting = [&] {
    const KltDetection d = tracker.plan_detection();
    int cells = 0;
    for (int c = 0; c < d.cells(); ++c) cells += d.wanted[c] > 0;
    return cells;
  };
  double shift = 0.0;
  int k = 1;
  for (; k < 40; ++k) {
    shift += 8.0;
    tracker.track_existing(frame(shift), nullptr, 0.1 * k);
    if (tracker.num_tracks() < 0.8 * filled) break;
    EXPECT_EQ(wanting(), 0) << "frame " << k << ": " << tracker.num_tracks() << " of " << filled;
    tracker.detect_new();
  }
  ASSERT_LT(k, 40) << "the pan never lost a fifth of the tracks";
  EXPECT_GT(k, 3);
  EXPECT_GT(wanting(), 0);
  // Always (1, the default): every frame's cells look, as before.
  KltTracker always(KltTrackerOptions(), 3000);
  always.track(frame(0.0), nullptr, 0.0);
  always.track_existing(frame(8.0), nullptr, 0.1);
  const KltDetection d = always.plan_detection();
  int cells = 0;
  for (int c = 0; c < d.cells(); ++c) cells += d.wanted[c] > 0;
  EXPECT_GT(cells, 0);
}

TEST(KltTracker, OnlyTheCellsThatLostTracksLookAgain) {
  // A still textured image: after the first frame's detection every cell keeps its tracks, and
  // none looks again; a patch painted flat takes a cell's tracks, and that cell alone looks.
  const cv::Mat texture = hybrid_vo::testing::blurred_noise(480, 640, 2.5);
  KltTrackerOptions options;
  options.redetect_lost_cells = true;
  KltTracker tracker(options, 3000);  // more than the texture's corners: no cell reaches its quota
  tracker.track(texture, nullptr, 0.0);
  ASSERT_GT(tracker.num_tracks(), 200);
  auto wanting = [&] {
    const KltDetection d = tracker.plan_detection();
    std::vector<int> cells;
    for (int c = 0; c < d.cells(); ++c)
      if (d.wanted[c] > 0) cells.push_back(c);
    return cells;
  };
  tracker.track_existing(texture, nullptr, 0.1);
  EXPECT_TRUE(wanting().empty());
  tracker.detect_new();
  cv::Mat painted = texture.clone();
  // Cell (2, 1) of the 8 x 6 grid spans x 160-240, y 80-160.
  cv::rectangle(painted, cv::Rect(170, 90, 60, 60), cv::Scalar(128), cv::FILLED);
  tracker.track_existing(painted, nullptr, 0.2);
  EXPECT_EQ(wanting(), std::vector<int>{1 * 8 + 2});
  // Without the option every cell short of its quota looks, every frame.
  KltTracker always(KltTrackerOptions(), 3000);
  always.track(texture, nullptr, 0.0);
  always.track_existing(texture, nullptr, 0.1);
  const KltDetection d = always.plan_detection();
  int cells = 0;
  for (int c = 0; c < d.cells(); ++c) cells += d.wanted[c] > 0;
  EXPECT_GT(cells, 40);
}

TEST(KltTracker, AlternateRedetectionFillsHalfTheCellsByTurns) {
  const cv::Mat texture = hybrid_vo::testing::blurred_noise(700, 1000, 2.5);
  auto frame = [&](int k) {  // a pan: features leave on one side, cells empty on the other
    const cv::Matx23d warp(1, 0, -150 + 12.0 * k, 0, 1, -100);
    cv::Mat image;
    cv::warpAffine(texture, image, warp, cv::Size(640, 480),
                   cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    return image;
  };
  KltTrackerOptions options;
  options.redetect_alternate = true;
  KltTracker tracker(options, 600);
  int previous_colour = -1;
  for (int k = 0; k < 6; ++k) {
    SCOPED_TRACE("frame " + std::to_string(k));
    tracker.track_existing(frame(k), nullptr, 0.1 * k);
    KltDetection d = tracker.plan_detection();
    int wanting[2] = {0, 0};  // cells wanting corners, by checkerboard colour
    for (int c = 0; c < d.cells(); ++c)
      if (d.wanted[c] > 0) ++wanting[(c % d.cols + c / d.cols) % 2];
    if (k == 0) {
      EXPECT_EQ(wanting[0] + wanting[1], d.cells());  // nothing tracked yet: every cell
    } else {
      ASSERT_TRUE((wanting[0] > 0) != (wanting[1] > 0)) << wanting[0] << " " << wanting[1];
      const int colour = wanting[0] > 0 ? 0 : 1;
      if (previous_colour >= 0) EXPECT_NE(colour, previous_colour);
      previous_colour = colour;
    }
    for (int c = 0; c < d.cells(); ++c) tracker.detect_cell(&d, c);
    tracker.add_detections(d);
  }
  tracker.reset();
  tracker.track_existing(frame(0), nullptr, 0.0);
  const KltDetection d = tracker.plan_detection();
  EXPECT_EQ(std::count_if(d.wanted.begin(), d.wanted.end(), [](int w) { return w > 0; }),
            d.cells());
}

TEST(KltTracker, SplitSearchesAndCellsGiveTheSameTracks) {
  const cv::Mat texture = hybrid_vo::testing::blurred_noise(700, 1000, 2.5);
  // Zooming in about a point left of centre: the flow differs across the image and features
  // leave it on the left, so tracks are lost and cells refilled unevenly.
  auto frame = [&](int k) {
    const double zoom = 1.0 + 0.03 * k;
    const cv::Matx23d warp(zoom, 0, (1 - zoom) * 300 - 150, 0, zoom, (1 - zoom) * 350 - 100);
    cv::Mat image;
    cv::warpAffine(texture, image, warp, cv::Size(640, 480),
                   cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    return image;
  };
  const KltTrackerOptions options;
  constexpr int kMaxFeatures = 300;
  KltTracker sequential(options, kMaxFeatures), reversed(options, kMaxFeatures),
      threaded(options, kMaxFeatures);
  WorkerThread worker;
  int capped = 0;
  for (int k = 0; k < 8; ++k) {
    const cv::Mat image = frame(k);
    const double stamp = 0.1 * k;
    std::vector<int64_t> ids_sequential, ids_reversed, ids_threaded;
    const std::vector<PointMatch> a = sequential.track_existing(image, &ids_sequential, stamp);
    const std::vector<PointMatch> b =
        reversed.track_existing(image, &ids_reversed, stamp, backwards);
    const std::vector<PointMatch> c =
        threaded.track_existing(image, &ids_threaded, stamp, worker.parallel());
    EXPECT_TRUE(same_points(a, b) && same_points(a, c)) << "frame " << k;
    EXPECT_TRUE(ids_sequential == ids_reversed && ids_sequential == ids_threaded) << "frame " << k;
    if (k > 0) {
      EXPECT_GT(a.size(), 100u);
    }
    // Does max_features leave less room than the cells want?
    const KltDetection plan = sequential.plan_detection();
    int wanted = 0;
    for (int w : plan.wanted) wanted += std::max(0, w);
    capped += wanted > kMaxFeatures - sequential.num_tracks();
    sequential.detect_new();
    reversed.detect_new(backwards);
    threaded.detect_new(worker.parallel());
    EXPECT_TRUE(same_tracker(sequential, reversed)) << "frame " << k;
    EXPECT_TRUE(same_tracker(sequential, threaded)) << "frame " << k;
  }
  EXPECT_GT(capped, 0) << "the cap on features never bound";
}

// Issue 30: the rendered corridor with plain walls (only edges, corners and floor joints;
// points find sensor noise). Each estimated pair's rotation error against the renderer's truth,
// for a preset, in degrees.
std::vector<double> plain_corridor_rotation_errors(const std::string& preset, int frames) {
  SequenceOptions options;
  options.out_bag = "unused.bag";
  options.frames = frames;
  options.supersampling = 1;
  options.texture = TextureStyle::kPlain;
  const Sequence seq = make_sequence(options);
  VisualOdometryOptions vo_options;
  EXPECT_TRUE(preset_options(preset, &vo_options.estimator));
  VisualOdometry vo(vo_options);
  std::vector<double> errors;
  for (int i = 0; i < frames; ++i) {
    VisualOdometryInput in;
    in.stamp = 1.0 + i / seq.options.rate;
    in.image = render_frame(seq, i).image;
    in.camera.pinhole = seq.camera;
    const VisualOdometryResult r = vo.process(in);
    if (r.status != VoStatus::kOk) continue;
    const int ref = static_cast<int>(std::lround((r.reference_stamp - 1.0) * seq.options.rate));
    const CameraPose a = frame_pose(seq, ref), b = frame_pose(seq, i);
    const Eigen::Matrix3d R = b.R_world_from_camera.transpose() * a.R_world_from_camera;
    errors.push_back(Eigen::AngleAxisd(r.motion.R * R.transpose()).angle() * 180.0 / M_PI);
  }
  return errors;
}

double median_of(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(LowTexture, LinesHalveTheRotationErrorOnPlainWalls) {
  constexpr int kPlainFrames = 60;  // along a corridor and through its first corner
  const std::vector<double> points = plain_corridor_rotation_errors("5pc", kPlainFrames);
  const std::vector<double> lines = plain_corridor_rotation_errors("hybrid+junc", kPlainFrames);
  ASSERT_GE(points.size(), kPlainFrames / 2u);
  ASSERT_GE(lines.size(), kPlainFrames / 2u);
  const double with_points = median_of(points), with_lines = median_of(lines);
  std::printf("median rotation error per pair: 5pc %.3f deg (%zu pairs), hybrid+junc %.3f deg "
              "(%zu pairs)\n",
              with_points, points.size(), with_lines, lines.size());
  EXPECT_LE(with_lines, 0.5 * with_points);
  EXPECT_LE(with_lines, 0.3);
}

// Issue 38: the map of world directions on the rendered plain corridor through its first 90-degree
// corner. Frames 0-14 see the corridor's three directions; around the corner the camera faces a
// blank wall (one or two segments, points on sensor noise), then the same three directions again,
// turned by 90 degrees, after some 10-20 degrees of drift.
struct MapRun {
  std::vector<VisualOdometryResult> results;
  std::vector<double> orientation_error_deg;  // per frame, against the first frame
  int blank_walls = 0, coasted = 0, reacquired = 0;
  double max_sigma_deg = 0.0;  // the orientation's largest sigma over the run
  // NEES against the truth: each estimated pair's rotation under the motion's covariance, each
  // estimated frame's orientation (against the first) under the pose covariance's rotation block.
  std::vector<double> pair_nees, orientation_nees;
};

// e^T C^-1 e of a rotation R against the truth T, the covariance of a left increment of R.
double rotation_nees(const Eigen::Matrix3d& R, const Eigen::Matrix3d& T, const Eigen::Matrix3d& C) {
  const Eigen::AngleAxisd error(Eigen::Matrix3d(R * T.transpose()));
  const Eigen::Vector3d w = error.angle() * error.axis();
  return w.dot(C.ldlt().solve(w));
}

double share_below(const std::vector<double>& v, double bound) {
  double inside = 0.0;
  for (const double x : v) inside += x < bound;
  return v.empty() ? 0.0 : inside / v.size();
}

// Honest enough: the pairs' rotation NEES median within [0.3, 6] (2.37 if exact) and 80 % of them
// inside the 95 % ellipsoid, the orientation's 80 %.
void expect_honest(const MapRun& run) {
  std::vector<double> pairs = run.pair_nees;
  std::nth_element(pairs.begin(), pairs.begin() + pairs.size() / 2, pairs.end());
  const double median = pairs.empty() ? NAN : pairs[pairs.size() / 2];
  const double inside = share_below(run.pair_nees, 7.815);
  const double orientation_inside = share_below(run.orientation_nees, 7.815);
  std::printf("pairs: NEES median %.2f, %.0f %% inside; orientation %.0f %% inside\n", median,
              100.0 * inside, 100.0 * orientation_inside);
  EXPECT_GE(median, 0.3);
  EXPECT_LE(median, 6.0);
  EXPECT_GE(inside, 0.8);
  EXPECT_GE(orientation_inside, 0.8);
}

// A run of VisualOdometry over rendered frames with its truth (camera into the first camera).
MapRun run_rendered(const Sequence& sequence, const std::vector<cv::Mat>& images,
                    const VisualOdometryOptions& options) {
  VisualOdometry vo(options);
  MapRun run;
  const CameraPose first = frame_pose(sequence, 0);
  std::vector<Eigen::Matrix3d> truth;
  for (size_t i = 0; i < images.size(); ++i) {
    VisualOdometryInput in;
    in.stamp = 1.0 + i / sequence.options.rate;
    in.image = images[i];
    in.camera.pinhole = sequence.camera;
    const VisualOdometryResult r = vo.process(in);
    truth.push_back(first.R_world_from_camera.transpose() *
                    frame_pose(sequence, static_cast<int>(i)).R_world_from_camera);
    run.orientation_error_deg.push_back(
        Eigen::AngleAxisd(r.R_wc.transpose() * truth.back()).angle() * 180.0 / M_PI);
    run.blank_walls += r.status == VoStatus::kOk && r.orientation.blank_wall;
    run.coasted += r.orientation.source == OrientationSource::kCoasted;
    run.reacquired += r.orientation.source == OrientationSource::kReacquired;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(r.orientation.covariance);
    run.max_sigma_deg =
        std::max(run.max_sigma_deg,
                 std::sqrt(std::max(0.0, eigen.eigenvalues().maxCoeff())) * 180.0 / M_PI);
    if (r.status == VoStatus::kOk) {
      const int reference = static_cast<int>(
          std::lround((r.reference_stamp - 1.0) * sequence.options.rate));
      if (reference >= 0 && reference < static_cast<int>(i) && r.motion_covariance_valid)
        run.pair_nees.push_back(rotation_nees(r.motion.R,
                                              truth.back().transpose() * truth[reference],
                                              r.motion_covariance.topLeftCorner<3, 3>()));
      run.orientation_nees.push_back(
          rotation_nees(r.R_wc, truth.back(), r.pose_covariance.bottomRightCorner<3, 3>()));
    }
    run.results.push_back(r);
  }
  return run;
}

class PlainCorner : public ::testing::Test {
 protected:
  static constexpr int kFrames = 60;

  static void SetUpTestSuite() {
    SequenceOptions options;
    options.out_bag = "unused.bag";
    options.frames = kFrames;
    options.supersampling = 1;
    options.texture = TextureStyle::kPlain;
    sequence_ = new Sequence(make_sequence(options));
    images_ = new std::vector<cv::Mat>();
    for (int i = 0; i < kFrames; ++i) images_->push_back(render_frame(*sequence_, i).image);
    VisualOdometryOptions with_map;
    EXPECT_TRUE(preset_options("hybrid+junc", &with_map.estimator));
    map_ = new MapRun(run(with_map));
    VisualOdometryOptions without = with_map;
    without.anchor_orientation = false;
    no_map_ = new MapRun(run(without));
    VisualOdometryOptions coasting = with_map;
    coasting.orientation.coast_blank_walls = true;
    coasting_ = new MapRun(run(coasting));
  }
  static void TearDownTestSuite() {
    delete map_;
    delete no_map_;
    delete coasting_;
    delete images_;
    delete sequence_;
  }

  static MapRun run(const VisualOdometryOptions& options) {
    return run_rendered(*sequence_, *images_, options);
  }

  static Sequence* sequence_;
  static std::vector<cv::Mat>* images_;
  static MapRun* map_;
  static MapRun* no_map_;
  static MapRun* coasting_;
};
Sequence* PlainCorner::sequence_ = nullptr;
std::vector<cv::Mat>* PlainCorner::images_ = nullptr;
MapRun* PlainCorner::map_ = nullptr;
MapRun* PlainCorner::no_map_ = nullptr;
MapRun* PlainCorner::coasting_ = nullptr;

TEST_F(PlainCorner, TheMapHoldsTheOrientationThroughTheCorner) {
  const double last = map_->orientation_error_deg.back();
  const double without = no_map_->orientation_error_deg.back();
  std::printf("orientation at frame %d: %.3f deg with the map, %.3f deg without; %d blank-wall "
              "pairs, %d re-acquisitions\n",
              kFrames - 1, last, without, map_->blank_walls, map_->reacquired);
  EXPECT_LE(last, 1.0);
  EXPECT_GE(without, 3.0) << "the corner no longer drifts without the map: the test lost its point";
  EXPECT_GE(map_->reacquired, 1);
  // The corridor's directions, found again after the turn, hold the last frame.
  const VisualOdometryResult& r = map_->results.back();
  EXPECT_NE(r.orientation.source, OrientationSource::kPair);
  EXPECT_GE(r.orientation.location.paired, 2);
}

// Across the blank wall the pairs' rotations rest on points on sensor noise: they are flagged, the
// orientation's uncertainty grows instead of trusting them (none of the corridor's textured frames
// before the corner is flagged), and the map takes the orientation back after the corner.
TEST_F(PlainCorner, BlankWallPairsAreFlaggedAndGrowTheUncertainty) {
  EXPECT_GE(map_->blank_walls, 3);
  EXPECT_GE(map_->max_sigma_deg, 3.0);
  int flagged_before_the_corner = 0;
  for (size_t i = 0; i < 12 && i < map_->results.size(); ++i)
    flagged_before_the_corner += map_->results[i].orientation.blank_wall;
  EXPECT_EQ(flagged_before_the_corner, 0);
}

// Coasting (coast_blank_walls): the blank wall is crossed on the last motion's rotation, each
// such pair counted, and the map takes the orientation back all the same.
TEST_F(PlainCorner, CoastingAcrossTheBlankWall) {
  std::printf("coasting: %d coasted pairs, orientation at frame %d %.3f deg\n", coasting_->coasted,
              kFrames - 1, coasting_->orientation_error_deg.back());
  EXPECT_GE(coasting_->coasted, 3);
  EXPECT_EQ(coasting_->coasted, coasting_->blank_walls);
  EXPECT_LE(coasting_->orientation_error_deg.back(), 1.0);
  EXPECT_EQ(map_->coasted, 0);  // off by default
}

// Issue 43: the covariances are honest on the plain corner, blank walls and all: the pairs'
// rotation NEES (3 if exact) neither claims more than the pairs know nor hides them under a
// blanket, and the orientation's error lies inside its 95 % ellipsoid (the refinement's own
// covariance, sigma^2 (J^T J)^-1, gave a median pair NEES of 15-20 here).
TEST_F(PlainCorner, TheCovariancesAreHonest) {
  ASSERT_GE(map_->pair_nees.size(), kFrames / 2u);
  expect_honest(*map_);
}

// The same on a textured corridor, where the pairs are a tenth as uncertain.
TEST(TexturedCorridor, TheCovariancesAreHonest) {
  SequenceOptions options;
  options.out_bag = "unused.bag";
  options.frames = 60;
  options.supersampling = 1;
  const Sequence sequence = make_sequence(options);
  std::vector<cv::Mat> images;
  for (int i = 0; i < options.frames; ++i) images.push_back(render_frame(sequence, i).image);
  VisualOdometryOptions odometry;
  ASSERT_TRUE(preset_options("hybrid+junc", &odometry.estimator));
  const MapRun run = run_rendered(sequence, images, odometry);
  ASSERT_GE(run.pair_nees.size(), 40u);
  expect_honest(run);
}

// A synthetic scene of a bright and a grey rectangle, shifted `shift` pixels to the right.
cv::Mat moving_rectangles(double shift, bool without_second = false) {
  cv::Mat image(240, 400, CV_8UC1, cv::Scalar(40));
  const cv::Matx23d move(1, 0, shift, 0, 1, 0);
  cv::Mat scene(240, 400, CV_8UC1, cv::Scalar(40));
  cv::rectangle(scene, cv::Rect(60, 50, 120, 90), cv::Scalar(200), cv::FILLED);
  if (!without_second) cv::rectangle(scene, cv::Rect(200, 120, 80, 80), cv::Scalar(120), cv::FILLED);
  cv::warpAffine(scene, image, move, image.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return image;
}

TEST(LineTracker, KeepsIdsThroughMotionAndAMissedFrameAndStartsAfreshBackwards) {
  const LineMatchingOptions matching = video_line_matching_options();
  LineTracker tracker;
  const LineFeatures first = detect_line_features(moving_rectangles(0.0), matching);
  ASSERT_GE(first.segments.size(), 6u);
  const std::vector<int64_t> first_ids = tracker.track(first, 0.0);
  // Constant motion of 6 px per frame: young tracks are found within their wider window, then
  // the prediction follows; every segment keeps its id.
  std::vector<int64_t> ids;
  LineFeatures current;
  for (int frame = 1; frame <= 4; ++frame) {
    current = detect_line_features(moving_rectangles(6.0 * frame), matching);
    LineTrackingStats stats;
    ids = tracker.track(current, 0.1 * frame, &stats);
    EXPECT_EQ(stats.started, 0) << "frame " << frame;
    EXPECT_EQ(stats.matched, static_cast<int>(current.segments.size())) << "frame " << frame;
  }
  std::vector<int64_t> sorted_first = first_ids, sorted_now = ids;
  std::sort(sorted_first.begin(), sorted_first.end());
  std::sort(sorted_now.begin(), sorted_now.end());
  EXPECT_EQ(sorted_first, sorted_now);

  // The second rectangle is missed once: its tracks coast and keep their ids when it is back.
  const LineFeatures missing = detect_line_features(moving_rectangles(30.0, true), matching);
  ASSERT_LT(missing.segments.size(), current.segments.size());
  LineTrackingStats stats;
  tracker.track(missing, 0.5, &stats);
  EXPECT_EQ(stats.started, 0);
  const LineFeatures back = detect_line_features(moving_rectangles(36.0), matching);
  const std::vector<int64_t> back_ids = tracker.track(back, 0.6, &stats);
  EXPECT_EQ(stats.started, 0);
  std::vector<int64_t> sorted_back = back_ids;
  std::sort(sorted_back.begin(), sorted_back.end());
  EXPECT_EQ(sorted_first, sorted_back);

  // Missed for longer than max_missed_frames: dropped, and new ids when it comes back.
  LineTrackerOptions options;
  for (int k = 0; k < options.max_missed_frames + 1; ++k)
    tracker.track(detect_line_features(moving_rectangles(42.0 + 6 * k, true), matching),
                  0.7 + 0.1 * k);
  tracker.track(detect_line_features(moving_rectangles(42.0 + 6 * (options.max_missed_frames + 1)),
                                     matching),
                0.7 + 0.1 * (options.max_missed_frames + 1), &stats);
  EXPECT_GT(stats.dropped + stats.started, 0);
  EXPECT_GT(stats.started, 0);

  // Time going backwards starts afresh: every segment gets a new track.
  const LineFeatures again = detect_line_features(moving_rectangles(0.0), matching);
  const std::vector<int64_t> again_ids = tracker.track(again, 0.0, &stats);
  EXPECT_EQ(stats.tracks, 0);
  EXPECT_EQ(stats.started, static_cast<int>(again.segments.size()));
  for (const int64_t id : again_ids)
    EXPECT_EQ(std::count(sorted_first.begin(), sorted_first.end(), id), 0);
}

// A sudden jump of 40 px (a turn starting): the rotation's prediction carries every track
// there; without it, the search keeps only the edges that slid along themselves and the
// descriptors re-identify the rest; with neither, those start afresh.
TEST(LineTracker, JumpsAreFollowedByTheRotationOrReidentified) {
  const LineMatchingOptions matching = video_line_matching_options();
  const LineFeatures before = detect_line_features(moving_rectangles(0.0), matching);
  const LineFeatures after = detect_line_features(moving_rectangles(40.0), matching);
  ASSERT_GE(before.segments.size(), 6u);
  ASSERT_EQ(before.segments.size(), after.segments.size());
  const int n = static_cast<int>(after.segments.size());
  Eigen::Matrix3d shift = Eigen::Matrix3d::Identity();
  shift(0, 2) = 40.0;
  auto run = [&](bool reidentify, const Eigen::Matrix3d& motion) {
    LineTrackerOptions options;
    options.reidentify = reidentify;
    LineTracker tracker(options, matching);
    tracker.track(before, 0.0);
    LineTrackingStats stats;
    tracker.track(after, 0.1, &stats, motion);
    return stats;
  };
  const LineTrackingStats searched = run(false, Eigen::Matrix3d::Identity());
  EXPECT_GT(searched.matched, 0) << "horizontal edges slid along themselves";
  EXPECT_LT(searched.matched, n) << "vertical edges jumped out of the search";
  EXPECT_EQ(searched.started, n - searched.matched);
  const LineTrackingStats reidentified = run(true, Eigen::Matrix3d::Identity());
  EXPECT_EQ(reidentified.matched, n);
  EXPECT_EQ(reidentified.reidentified, n - searched.matched);
  const LineTrackingStats predicted = run(true, shift);
  EXPECT_EQ(predicted.matched, n);
  EXPECT_EQ(predicted.reidentified, 0);
}

TEST(LineTracker, NeverTakesAnEdgeOfOppositeContrastAndHandlesEmptyFrames) {
  const LineMatchingOptions matching = video_line_matching_options();
  // A bright bar on dark ground, then the same bar dark on bright ground: the same lines, every
  // edge of the opposite contrast.
  cv::Mat bright(200, 200, CV_8UC1, cv::Scalar(40)), dark(200, 200, CV_8UC1, cv::Scalar(200));
  cv::rectangle(bright, cv::Rect(60, 40, 60, 120), cv::Scalar(200), cv::FILLED);
  cv::rectangle(dark, cv::Rect(60, 40, 60, 120), cv::Scalar(40), cv::FILLED);
  LineTracker tracker;
  const LineFeatures a = detect_line_features(bright, matching);
  ASSERT_GE(a.segments.size(), 2u);
  tracker.track(a, 0.0);
  LineTrackingStats stats;
  const LineFeatures b = detect_line_features(dark, matching);
  ASSERT_GE(b.segments.size(), 2u);
  tracker.track(b, 0.1, &stats);
  EXPECT_EQ(stats.matched, 0);
  EXPECT_EQ(stats.started, static_cast<int>(b.segments.size()));
  // An empty frame matches nothing and starts nothing; tracks coast.
  EXPECT_TRUE(tracker.track(LineFeatures(), 0.2, &stats).empty());
  EXPECT_EQ(stats.matched + stats.started, 0);
  EXPECT_GT(tracker.num_tracks(), 0);
}

// Issue 30: a cell of white wall still yields goodFeaturesToTrack's relative "corners" of faint
// texture; with min_corner_gradient only real corners are tracked.
TEST(KltTracker, FaintTextureIsNotTrackedStrongCornersAre) {
  cv::Mat image(240, 320, CV_8UC1, cv::Scalar(180));
  cv::Mat texture(240, 320, CV_8UC1);
  cv::randu(texture, 0, 3);  // +-1.5 grey levels of "fabric"
  cv::GaussianBlur(texture, texture, cv::Size(5, 5), 1.5);
  image += texture;
  for (int k = 0; k < 4; ++k)  // four dark squares: 16 strong corners
    cv::rectangle(image, cv::Rect(40 + 60 * k, 100, 30, 30), cv::Scalar(60), cv::FILLED);
  KltTrackerOptions options;
  KltTracker all(options, 300);
  all.track(image);
  options.min_corner_gradient = 1.5;
  KltTracker strong(options, 300);
  strong.track(image);
  EXPECT_GT(all.num_tracks(), 60) << "every cell finds its faint corners";
  EXPECT_GE(strong.num_tracks(), 12);
  EXPECT_LE(strong.num_tracks(), 20);
  for (const cv::Point2f& p : strong.points())
    EXPECT_TRUE(p.y > 95 && p.y < 135) << p;  // on the squares only
}

TEST(WorkerThread, RunsJobsInOrderAndRethrowsTheirErrors) {
  for (const bool concurrent : {true, false}) {
    WorkerThread worker(concurrent);
    EXPECT_EQ(worker.concurrent(), concurrent);
    std::vector<int> order;
    {
      WorkerJob first = worker.submit([&] { order.push_back(1); });
      WorkerJob second = worker.submit([&] { order.push_back(2); });
      second.get();
      first.get();
    }
    EXPECT_EQ(order, (std::vector<int>{1, 2}));
    WorkerJob failing = worker.submit([] { throw std::runtime_error("job failed"); });
    EXPECT_THROW(failing.get(), std::runtime_error);
    // An empty handle waits for nothing; the worker still runs jobs after a failure.
    WorkerJob empty;
    EXPECT_NO_THROW(empty.get());
    int value = 0;
    worker.submit([&] { value = 7; }).get();
    EXPECT_EQ(value, 7);
  }
}

TEST(WorkerThread, SharedLoopsRunEachIndexOnceAndRethrow) {
  for (const bool concurrent : {true, false}) {
    WorkerThread worker(concurrent);
    // A job that keeps the worker busy until released (a sequential worker has none: it runs
    // shared loops only when they are joined).
    std::promise<void> release;
    auto occupy = [&] {
      release = std::promise<void>();
      std::shared_future<void> released = release.get_future().share();
      return concurrent ? worker.submit([released] { released.wait(); }) : WorkerJob();
    };
    // The worker is busy when the loop is shared: the caller runs what it has not taken.
    WorkerJob busy = occupy();
    std::vector<int> runs(100, 0);
    SharedLoop loop = worker.share(100, [&](int i) { ++runs[i]; });
    loop.join();
    EXPECT_EQ(runs, std::vector<int>(100, 1));
    release.set_value();
    busy.get();
    // Both threads at once.
    std::vector<std::atomic<int>> counts(1000);
    worker.parallel_for(1000, [&](int i) { ++counts[i]; });
    for (const std::atomic<int>& c : counts) EXPECT_EQ(c.load(), 1);
    // The first error is rethrown once every index has run or been left.
    std::atomic<int> ran{0};
    EXPECT_THROW(worker.parallel_for(50,
                                     [&](int i) {
                                       ++ran;
                                       if (i == 7) throw std::runtime_error("index failed");
                                     }),
                 std::runtime_error);
    EXPECT_EQ(ran.load(), 50);
    // A cancelled loop runs no index that had not started.
    busy = occupy();
    int started = 0;
    SharedLoop cancelled = worker.share(10, [&](int) { ++started; });
    cancelled.cancel();
    release.set_value();
    busy.get();
    EXPECT_EQ(started, 0);
    // An empty loop, and an empty handle.
    worker.parallel_for(0, [](int) { FAIL(); });
    SharedLoop empty;
    EXPECT_NO_THROW(empty.join());
  }
}

}  // namespace
