// An answer for every frame (VisualOdometry without ROS): a camera at rest, a wheeled robot's
// camera turning in place about a point behind it, a start from rest, small stereo baselines at
// 30 Hz, and a pan in place over a photograph made here. Every frame after the first has a
// pose; where the data show no translation the pair is rotation-only, the mono position stays
// and the stereo one follows the stereo points; the orientation follows the truth.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/odometry/visual_odometry.h"
#include "hybrid_vo/render/pan_motion.h"
#include "hybrid_vo/render/photo_pan.h"
#include "hybrid_vo/render/sequence.h"

namespace {

using namespace hybrid_vo;
using namespace hybrid_vo::render;

constexpr double kDeg = 180.0 / M_PI;

struct OdometryRun {
  std::vector<VisualOdometryResult> results;
  std::vector<Eigen::Matrix3d> R_true;  // camera into the first camera
  std::vector<Eigen::Vector3d> c_true;  // camera centre in the first camera
};

VisualOdometryOptions sequential() {
  VisualOdometryOptions o;
  o.concurrent = false;
  return o;
}

// A rendered sequence of `motion` through the odometry, mono or stereo.
OdometryRun run_rendered(Motion motion, int frames, double rate, bool stereo, uint64_t seed,
                         const VisualOdometryOptions& vo_options = sequential(),
                         bool room = false) {
  SequenceOptions options;
  options.out_bag = "unused.bag";
  options.frames = frames;
  options.rate = rate;
  options.width = 480;
  options.height = 360;
  options.supersampling = 1;
  options.stereo = stereo;
  options.motion = motion;
  options.seed = seed;
  if (room || motion == Motion::kTurn || motion == Motion::kHandheld)
    options.scene = SceneType::kRoom;
  if (motion == Motion::kHandheld) options.speed = 0.09;  // the command line's default
  const Sequence seq = make_sequence(options);
  VisualOdometry vo(vo_options);
  OdometryRun run;
  const CameraPose first = frame_pose(seq, 0);
  for (int i = 0; i < frames; ++i) {
    VisualOdometryInput in;
    in.stamp = 1.0 + i / rate;
    in.image = render_frame(seq, i).image;
    in.camera.pinhole = seq.camera;
    if (stereo) {
      in.right_image = render_frame(seq, i, true).image;
      in.baseline_m = options.baseline;
    }
    run.results.push_back(vo.process(in));
    const CameraPose p = frame_pose(seq, i);
    run.R_true.push_back(first.R_world_from_camera.transpose() * p.R_world_from_camera);
    run.c_true.push_back(first.to_camera(p.centre));
  }
  return run;
}

double orientation_error_deg(const OdometryRun& run, int i) {
  return rotation_error(run.results[i].R_wc, run.R_true[i]) * kDeg;
}

int answered_frames(const OdometryRun& run) {
  int n = 0;
  for (size_t i = 1; i < run.results.size(); ++i) n += answered(run.results[i].status);
  return n;
}

int rotation_only_frames(const OdometryRun& run) {
  int n = 0;
  for (const VisualOdometryResult& r : run.results) n += r.status == VoStatus::kRotationOnly;
  return n;
}

TEST(Answers, AtRestEveryFrameIsRotationOnlyAndThePoseStays) {
  for (const bool stereo : {false, true}) {
    const OdometryRun run = run_rendered(Motion::kRest, 16, 20.0, stereo, 3);
    const int frames = static_cast<int>(run.results.size());
    EXPECT_EQ(answered_frames(run), frames - 1) << (stereo ? "stereo" : "mono");
    EXPECT_GE(rotation_only_frames(run), frames - 2);
    for (int i = 1; i < frames; ++i) {
      const VisualOdometryResult& r = run.results[i];
      EXPECT_LT(orientation_error_deg(run, i), 0.05) << i;
      // Mono: only a baseline moves the position; stereo: measured, zero within its noise.
      EXPECT_LT(r.centre.norm(), stereo ? 0.01 : 1e-12) << i;
      EXPECT_FALSE(r.baseline) << i;
      EXPECT_TRUE(r.motion_covariance_valid) << i;
      EXPECT_EQ(r.scale_known, stereo) << i;
      EXPECT_TRUE(r.pose_covariance.allFinite()) << i;
    }
  }
}

// A wheeled robot's camera, 0.2 m in front of the axis it turns about at 30 deg/s: stereo
// follows the arc (the stereo points give each pair without a baseline its translation), mono
// answers every frame with its rotation.
TEST(Answers, TurningInPlaceWithALeverArm) {
  const OdometryRun stereo = run_rendered(Motion::kTurn, 60, 30.0, true, 2);
  const int frames = static_cast<int>(stereo.results.size());
  EXPECT_EQ(answered_frames(stereo), frames - 1);
  double worst = 0.0;
  int far = 0;
  for (int i = 1; i < frames; ++i) {
    EXPECT_LT(orientation_error_deg(stereo, i), 0.5) << i;
    const Eigen::Vector3d c = stereo.results[i].centre, t = stereo.c_true[i];
    if (t.norm() < 0.05) continue;
    ++far;
    worst = std::max(worst, std::atan2(c.cross(t).norm(), c.dot(t)) * kDeg);
  }
  ASSERT_GT(far, 10);
  EXPECT_LT(worst, 8.0);
  const double ratio = stereo.results.back().centre.norm() / stereo.c_true.back().norm();
  EXPECT_NEAR(ratio, 1.0, 0.05);
  RecordProperty("direction_from_start_worst_deg", std::to_string(worst));
  RecordProperty("length_ratio", std::to_string(ratio));

  const OdometryRun mono = run_rendered(Motion::kTurn, 60, 30.0, false, 2);
  EXPECT_EQ(answered_frames(mono), frames - 1);
  for (int i = 1; i < frames; ++i) EXPECT_LT(orientation_error_deg(mono, i), 1.0) << i;
}

// A camera turning at 30 deg/s with keyframe_max_turn_deg: no frame is answered against a
// keyframe it has turned further from than the limit and one frame's turn, every frame is
// answered, and the orientation holds; without the limit the keyframe stays over more.
TEST(Answers, AKeyframeTurnedTooFarIsReplaced) {
  const double rate = 30.0, limit = 5.0;
  VisualOdometryOptions limited = sequential();
  limited.keyframe_max_turn_deg = limit;
  const OdometryRun run = run_rendered(Motion::kTurn, 60, rate, false, 2, limited);
  const OdometryRun free = run_rendered(Motion::kTurn, 60, rate, false, 2);
  auto widest = [&](const OdometryRun& r) {
    double most = 0.0;
    for (size_t i = 1; i < r.results.size(); ++i) {
      const int ref = static_cast<int>(std::lround((r.results[i].reference_stamp - 1.0) * rate));
      if (ref < 0 || ref >= static_cast<int>(i)) continue;
      const Eigen::AngleAxisd turn(r.R_true[i].transpose() * r.R_true[ref]);
      most = std::max(most, turn.angle() * kDeg);
    }
    return most;
  };
  const int frames = static_cast<int>(run.results.size());
  EXPECT_EQ(answered_frames(run), frames - 1);
  for (int i = 1; i < frames; ++i) EXPECT_LT(orientation_error_deg(run, i), 1.0) << i;
  const double per_frame = 30.0 / rate;
  EXPECT_LE(widest(run), limit + per_frame + 0.1);
  EXPECT_GT(widest(free), limit + per_frame + 0.1);
  RecordProperty("widest_link_deg", std::to_string(widest(run)) + " (" +
                                        std::to_string(widest(free)) + " without the limit)");
}

// Still for a second, then walking: the stereo position stays within a centimetre while the
// camera stands, and has the walk's length at the end.
TEST(Answers, StartingFromRest) {
  const OdometryRun run = run_rendered(Motion::kRamp, 45, 15.0, true, 4);
  const int frames = static_cast<int>(run.results.size());
  EXPECT_EQ(answered_frames(run), frames - 1);
  for (int i = 1; i < 15; ++i) EXPECT_LT(run.results[i].centre.norm(), 0.01) << i;
  const double ratio = run.results.back().centre.norm() / run.c_true.back().norm();
  EXPECT_GT(run.c_true.back().norm(), 1.0);
  EXPECT_NEAR(ratio, 1.0, 0.05);
}

// Walking through a room at 30 Hz the pairs have a few pixels of parallax: their epipolar
// direction is poor, the stereo points' depths are not. Where the stereo points' translation is
// clearly the better (stereo_translation_margin) the pair takes it: the pairs' translation
// direction (median) and the position at the end are nearer the truth than with the epipolar
// direction alone (seeds 5-7: 1.5-2.8 against 3.8-11.5 degrees).
TEST(Answers, SmallBaselinesTakeTheStereoPointsTranslation) {
  auto errors = [](const OdometryRun& run, double rate) {
    std::vector<double> pair_errors;
    for (size_t i = 1; i < run.results.size(); ++i) {
      const VisualOdometryResult& r = run.results[i];
      const int ref = static_cast<int>(std::lround((r.reference_stamp - 1.0) * rate));
      if (!r.baseline || !r.scale_known || ref < 0 || ref >= static_cast<int>(i)) continue;
      const Eigen::Vector3d t_true = run.R_true[i].transpose() * (run.c_true[ref] - run.c_true[i]);
      pair_errors.push_back(std::atan2(r.motion.t.cross(t_true).norm(), r.motion.t.dot(t_true)) * kDeg);
    }
    std::sort(pair_errors.begin(), pair_errors.end());
    return std::make_pair(pair_errors.empty() ? NAN : pair_errors[pair_errors.size() / 2],
                          (run.results.back().centre - run.c_true.back()).norm());
  };
  VisualOdometryOptions epipolar = sequential();
  epipolar.stereo_translation_margin = 0.0;
  const auto [pair_with, end_with] =
      errors(run_rendered(Motion::kWalk, 40, 30.0, true, 5, sequential(), true), 30.0);
  const auto [pair_without, end_without] =
      errors(run_rendered(Motion::kWalk, 40, 30.0, true, 5, epipolar, true), 30.0);
  EXPECT_LT(pair_with, 0.8 * pair_without);
  EXPECT_LT(end_with, end_without);
  RecordProperty("pair_direction_error_deg", std::to_string(pair_with) + " (" +
                                                 std::to_string(pair_without) + " epipolar)");
  RecordProperty("end_error_m", std::to_string(end_with) + " (" + std::to_string(end_without) + ")");
}

// A slow hand-held camera at 30 Hz (issue 53): 9 cm/s, looking around. Its parallax after the
// rotation grows by a fraction of a pixel a frame; the keyframe stays until it has
// keyframe_parallax_px of it, so that most frames after the first second are answered with a
// baseline, and the mono position moves. Replacing the keyframe once 30 % of its points are
// lost, as before, left almost every pair without one.
TEST(Answers, ASlowHandheldCameraKeepsItsKeyframeUntilThereIsParallax) {
  auto with_baseline = [](const OdometryRun& run) {
    int n = 0, after = 0;
    for (size_t i = 31; i < run.results.size(); ++i) {
      ++after;
      n += run.results[i].baseline;
    }
    return static_cast<double>(n) / after;
  };
  const int frames = 55;
  const OdometryRun now = run_rendered(Motion::kHandheld, frames, 30.0, false, 1);
  VisualOdometryOptions before = sequential();
  before.keyframe_parallax_px = 0.0;
  before.keyframe_overlap = 0.7;
  const OdometryRun old = run_rendered(Motion::kHandheld, frames, 30.0, false, 1, before);
  EXPECT_EQ(answered_frames(now), frames - 1);
  EXPECT_GE(with_baseline(now), 0.6);
  EXPECT_LT(with_baseline(old), 0.5 * with_baseline(now));
  EXPECT_GT(now.results.back().centre.norm(), 0.0);
  for (int i = 1; i < frames; ++i) EXPECT_LT(orientation_error_deg(now, i), 0.5) << i;
  RecordProperty("with_baseline", std::to_string(with_baseline(now)) + " (" +
                                      std::to_string(with_baseline(old)) + " before)");
}

// The same camera, longer (issue 58): after the first second every pair has its translation, from
// its baseline or, without one, from the keyframe's depths; the path keeps one scale (the first
// pair with a baseline's), and the position's covariance holds that scale's drift. Before, the
// pairs of a keyframe without depths all had the same length, and those right after a new
// keyframe none: the distance from the start over the truth's went from 12.7 to 4.1 and back.
TEST(Answers, ASlowHandheldCameraKeepsOneScale) {
  const int frames = 100;
  const OdometryRun run = run_rendered(Motion::kHandheld, frames, 30.0, false, 1);
  int after = 0, translated = 0, unit_frame = -1;
  std::vector<double> ratios, nees;
  for (int i = 1; i < frames; ++i) {
    const VisualOdometryResult& r = run.results[i];
    ASSERT_TRUE(answered(r.status)) << i;
    if (i >= 30) {
      ++after;
      translated += r.baseline || r.translation_from_depths;
    }
    if (unit_frame < 0 && r.baseline) unit_frame = i;
    if (unit_frame < 0) continue;
    // The unit: the first pair with a baseline's length over the truth's.
    const double unit = run.results[unit_frame].centre.norm() / run.c_true[unit_frame].norm();
    const Eigen::Vector3d e = r.centre - unit * run.c_true[i];
    const Eigen::Matrix3d P = r.pose_covariance.topLeftCorner<3, 3>();
    ASSERT_TRUE(P.allFinite()) << i;
    nees.push_back(e.dot(P.ldlt().solve(e)));
    if (i > unit_frame + 10) ratios.push_back(r.centre.norm() / run.c_true[i].norm() / unit);
  }
  ASSERT_GT(unit_frame, 0);
  EXPECT_GE(translated, 0.9 * after);
  ASSERT_FALSE(ratios.empty());
  const auto [low, high] = std::minmax_element(ratios.begin(), ratios.end());
  EXPECT_GT(*low, 0.8);
  EXPECT_LT(*high, 1.25);
  std::sort(nees.begin(), nees.end());
  const double median = nees[nees.size() / 2];
  EXPECT_GT(median, 0.3);  // 3 dof: 2.37 for an honest covariance
  EXPECT_LT(median, 8.0);
  RecordProperty("translated", std::to_string(translated) + " of " + std::to_string(after));
  RecordProperty("scale_ratio", std::to_string(*low) + " to " + std::to_string(*high));
  RecordProperty("position_nees_median", std::to_string(median));
}

// The same camera (issue 58): the frames just after a new keyframe see too little of its
// baseline; paired with the keyframe before, which they see from a baseline, they have their
// translation from the epipolar geometry too. Their pairs' direction holds against the truth
// between that keyframe and the frame, and they make no keyframe.
TEST(Answers, ASlowHandheldCameraPairsWithTheKeyframeBefore) {
  // A nearer next keyframe than the default's 7 px, so that the small render has a few.
  const int frames = 150;
  const double rate = 30.0;
  VisualOdometryOptions with = sequential();
  with.keyframe_parallax_px = 4.0;
  VisualOdometryOptions without = with;
  without.previous_keyframe_parallax_px = 0.0;
  const OdometryRun run = run_rendered(Motion::kHandheld, frames, rate, false, 1, with);
  const OdometryRun old = run_rendered(Motion::kHandheld, frames, rate, false, 1, without);
  auto baselines = [](const OdometryRun& r) {
    int n = 0;
    for (int i = 30; i < static_cast<int>(r.results.size()); ++i) n += r.results[i].baseline;
    return n;
  };
  int last_keyframe = 0, before = 0;
  std::vector<double> direction_errors;
  for (int i = 1; i < frames; ++i) {
    const VisualOdometryResult& r = run.results[i];
    ASSERT_TRUE(answered(r.status)) << i;
    const int reference = static_cast<int>(std::lround((r.reference_stamp - 1.0) * rate));
    if (reference < last_keyframe) {
      ++before;
      EXPECT_TRUE(r.baseline) << i;
      EXPECT_TRUE(r.paired_with_keyframe_before) << i;
      EXPECT_FALSE(r.became_keyframe) << i;
      // The truth's motion from that keyframe's camera to this one, in the keyframe's.
      const Eigen::Vector3d t_true =
          run.R_true[i].transpose() * (run.c_true[reference] - run.c_true[i]);
      const Eigen::Vector3d t = r.motion.t;
      ASSERT_GT(t.norm(), 0.0) << i;
      direction_errors.push_back(
          std::acos(std::clamp(t.normalized().dot(t_true.normalized()), -1.0, 1.0)) * kDeg);
    }
    else
      EXPECT_FALSE(r.paired_with_keyframe_before) << i;
    if (r.became_keyframe) last_keyframe = i;
    EXPECT_LT(orientation_error_deg(run, i), 0.5) << i;
  }
  ASSERT_GT(before, 5);
  EXPECT_GE(baselines(run), 0.9 * (frames - 30));
  EXPECT_LT(baselines(old), baselines(run));
  std::sort(direction_errors.begin(), direction_errors.end());
  EXPECT_LT(direction_errors[direction_errors.size() / 2], 10.0);
  RecordProperty("with_baseline", std::to_string(baselines(run)) + " of " +
                                      std::to_string(frames - 30) + " (" +
                                      std::to_string(baselines(old)) + " without)");
  RecordProperty("paired_with_the_keyframe_before", before);
  RecordProperty("direction_error_median_deg",
                 std::to_string(direction_errors[direction_errors.size() / 2]));
}

// A photograph: grey blocks of every size and brightness, with their edges in a few directions.
cv::Mat make_photo(int width, int height) {
  cv::Mat photo(height, width, CV_8UC1, cv::Scalar(90));
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> x(0, width - 1), y(0, height - 1), size(8, 160), grey(0, 255);
  for (int k = 0; k < 2500; ++k) {
    const cv::Point a(x(rng), y(rng));
    cv::rectangle(photo, a, a + cv::Point(size(rng), size(rng)), cv::Scalar(grey(rng)), cv::FILLED);
  }
  return photo;
}

// A pan in place: the virtual camera turns about its centre inside the photograph, which it sees
// through the exact homography of a pure rotation. Every frame is answered, the mono position
// never moves, the orientation stays within 0.1 degrees of the truth, and the rotation-only
// pairs' covariance holds their error.
TEST(Answers, APanInPlaceOverAPhotograph) {
  const PinholeCamera photo_camera(1380.0, 1380.0, 767.5, 511.5, 1536, 1024);
  const PinholeCamera camera(500.0, 500.0, 239.5, 179.5, 480, 360);
  const PhotoPan pan(make_photo(photo_camera.width, photo_camera.height), photo_camera, camera,
                     1.0, 5);
  PanMotionOptions motion_options;
  motion_options.frames = 45;
  motion_options.yaw_deg = 6.0;
  motion_options.pitch_deg = 2.0;
  motion_options.roll_deg = 1.5;
  const PanMotion motion = make_pan_motion(motion_options);
  VisualOdometry vo(sequential());
  int answered_count = 0, rotation_only = 0, inside = 0, with_covariance = 0;
  for (int i = 0; i < motion_options.frames; ++i) {
    VisualOdometryInput in;
    in.stamp = 1.0 + motion.times[i];
    in.image = pan.render_frame(motion, i);
    in.camera.pinhole = camera;
    const VisualOdometryResult r = vo.process(in);
    if (i == 0) continue;
    answered_count += answered(r.status);
    rotation_only += r.status == VoStatus::kRotationOnly;
    EXPECT_EQ(r.centre.norm(), 0.0) << i;
    EXPECT_LT(rotation_error(r.R_wc, motion.R_first_from_camera(i)) * kDeg, 0.1) << i;
    if (r.status != VoStatus::kRotationOnly || !r.motion_covariance_valid) continue;
    // The pair's rotation against the truth between its keyframe and this frame.
    const int reference = static_cast<int>(std::lround((r.reference_stamp - 1.0) * motion_options.rate));
    const Eigen::Matrix3d R_true =
        motion.R_first_from_camera(i).transpose() * motion.R_first_from_camera(reference);
    const Eigen::AngleAxisd e(Eigen::Matrix3d(r.motion.R * R_true.transpose()));
    const Eigen::Vector3d w = e.angle() * e.axis();
    ++with_covariance;
    inside += w.dot(r.motion_covariance.topLeftCorner<3, 3>().inverse() * w) < 7.815;
  }
  EXPECT_EQ(answered_count, motion_options.frames - 1);
  EXPECT_GE(rotation_only, (motion_options.frames - 1) / 2);
  ASSERT_GT(with_covariance, 10);
  EXPECT_GE(inside, 0.8 * with_covariance);
}

}  // namespace
