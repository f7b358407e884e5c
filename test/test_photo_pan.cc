// The pan inside a photograph (hybrid_vo_render_pan), on a synthetic photograph made here: the
// homography sends each virtual pixel's ray, turned, to the right photograph pixel, and the
// rendered views show the photograph's marks where it says; the pan keeps its amplitudes and
// its largest step, reverses slowly; dropped frames; the poses through the KITTI writer and
// reader; the options and their errors.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <opencv2/imgproc.hpp>

#include "file_test_utils.h"
#include "hybrid_vo/datasets/kitti_writer.h"
#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/render/imaging.h"
#include "hybrid_vo/render/pan_motion.h"
#include "hybrid_vo/render/pan_options.h"
#include "hybrid_vo/render/photo_pan.h"

namespace {

using namespace hybrid_vo;
using namespace hybrid_vo::render;
using hybrid_vo::testing::contains;
using hybrid_vo::testing::TempDir;

// The Strecha photographs' proportions at half size: each virtual pixel covers 2.76 of them.
const PinholeCamera kPhoto(1380.0, 1382.0, 760.3, 503.4, 1536, 1024);
const PinholeCamera kCamera(500.0, 500.0, 159.5, 119.5, 320, 240);

// Dark, with bright Gaussian marks (sigma 6 photograph pixels) on a grid.
std::vector<Eigen::Vector2d> mark_positions() {
  std::vector<Eigen::Vector2d> marks;
  for (double y = 100.3; y < kPhoto.height - 50; y += 97.0)
    for (double x = 120.7; x < kPhoto.width - 50; x += 113.0) marks.emplace_back(x, y);
  return marks;
}

cv::Mat make_marked_photo() {
  cv::Mat photo(kPhoto.height, kPhoto.width, CV_32FC1, cv::Scalar(20.0));
  for (const Eigen::Vector2d& m : mark_positions()) {
    const int x0 = static_cast<int>(m.x()), y0 = static_cast<int>(m.y());
    for (int y = y0 - 30; y <= y0 + 30; ++y)
      for (int x = x0 - 30; x <= x0 + 30; ++x)
        photo.at<float>(y, x) += static_cast<float>(
            200.0 * std::exp(-(Eigen::Vector2d(x, y) - m).squaredNorm() / (2.0 * 36.0)));
  }
  cv::Mat grey;
  photo.convertTo(grey, CV_8U);
  return grey;
}

const cv::Mat& marked_photo() {
  static const cv::Mat photo = make_marked_photo();
  return photo;
}

TEST(PhotoPan, HomographySendsTheTurnedRayToItsPhotographPixel) {
  const Eigen::Matrix3d R = pan_rotation(5.0, -2.0, 1.5);
  const Eigen::Matrix3d H = pan_homography(kPhoto, kCamera, R);
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0, 0), Eigen::Vector2d(159.5, 119.5),
                                   Eigen::Vector2d(300.25, 17.5), Eigen::Vector2d(319, 239)}) {
    const Eigen::Vector3d ray = kCamera.K_inverse() * p.homogeneous();
    const Eigen::Vector3d in_photo = R * ray;  // the same ray in the photograph camera's frame
    const Eigen::Vector2d expected = kPhoto.denormalize(in_photo.hnormalized());
    EXPECT_LT(((H * p.homogeneous()).hnormalized() - expected).norm(), 1e-9);
  }
  // Turned right and up, the view's centre lands right of and above the photograph's.
  const Eigen::Vector2d centre = (pan_homography(kPhoto, kCamera, pan_rotation(4.0, 2.0, 0.0)) *
                                  Eigen::Vector3d(kCamera.cx, kCamera.cy, 1.0))
                                     .hnormalized();
  EXPECT_GT(centre.x(), kPhoto.cx + 90.0);
  EXPECT_LT(centre.y(), kPhoto.cy - 45.0);
}

TEST(PhotoPan, SameCameraUnturnedGivesThePhotograph) {
  const cv::Mat& photo = marked_photo();
  const PhotoPan pan(photo, kPhoto, kPhoto, 0.0, 1);
  EXPECT_EQ(pan.prefilter_sigma(), 0.0);
  const cv::Mat view = pan.render(Eigen::Matrix3d::Identity(), 0);
  ASSERT_EQ(view.size(), photo.size());
  EXPECT_EQ(cv::norm(view, photo, cv::NORM_INF), 0.0);
}

// Each mark appears where the inverse homography puts it, to a few hundredths of a pixel.
TEST(PhotoPan, MarksAppearWhereTheHomographyPutsThem) {
  const cv::Mat& photo = marked_photo();
  const PhotoPan pan(photo, kPhoto, kCamera, 0.0, 1);
  EXPECT_NEAR(pan.prefilter_sigma(), 0.5 * 1381.0 / 500.0, 1e-12);
  int measured = 0;
  for (const Eigen::Matrix3d& R :
       {pan_rotation(0, 0, 0), pan_rotation(6.0, 2.5, -1.8), pan_rotation(-7.0, -2.0, 2.0)}) {
    const cv::Mat view = pan.render(R, 3);
    const Eigen::Matrix3d H_inv = pan_homography(kPhoto, kCamera, R).inverse();
    for (const Eigen::Vector2d& mark : mark_positions()) {
      const Eigen::Vector2d q = (H_inv * mark.homogeneous()).hnormalized();
      if (q.x() < 8 || q.y() < 8 || q.x() > kCamera.width - 9 || q.y() > kCamera.height - 9)
        continue;
      double sum = 0.0;
      Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
      const int x0 = static_cast<int>(std::lround(q.x())),
                y0 = static_cast<int>(std::lround(q.y()));
      for (int y = y0 - 7; y <= y0 + 7; ++y)
        for (int x = x0 - 7; x <= x0 + 7; ++x) {
          const double w = std::max(0.0, view.at<uchar>(y, x) - 20.0);
          sum += w;
          centroid += w * Eigen::Vector2d(x, y);
        }
      ASSERT_GT(sum, 0.0);
      EXPECT_LT((centroid / sum - q).norm(), 0.05) << "mark " << mark.transpose();
      ++measured;
    }
  }
  EXPECT_GT(measured, 6);
}

TEST(PhotoPan, NoiseDiffersPerFrameAndRepeats) {
  const cv::Mat& photo = marked_photo();
  const PhotoPan pan(photo, kPhoto, kCamera, 2.0, 7);
  const Eigen::Matrix3d R = pan_rotation(1.0, 0.5, 0.0);
  const cv::Mat a = pan.render(R, 4), b = pan.render(R, 4), c = pan.render(R, 5);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  const double mean_change = cv::norm(a, c, cv::NORM_L1) / a.total();
  EXPECT_GT(mean_change, 1.5);  // two noises of sigma 2: 2.26 apart on average
  EXPECT_LT(mean_change, 3.0);
}

// The sum of squared gradients: lower where the image is smeared.
double gradient_energy(const cv::Mat& image) {
  cv::Mat gx, gy;
  cv::Sobel(image, gx, CV_32F, 1, 0);
  cv::Sobel(image, gy, CV_32F, 0, 1);
  return cv::norm(gx, cv::NORM_L2SQR) + cv::norm(gy, cv::NORM_L2SQR);
}

TEST(PhotoPan, CleanFramesAreTheInstantsViews) {
  PanMotionOptions options;
  options.frames = 20;
  const PanMotion motion = make_pan_motion(options);
  const PhotoPan pan(marked_photo(), kPhoto, kCamera, 1.0, 3);
  for (int i : {0, 7, 19}) {
    ASSERT_EQ(pan.exposure_rotations(motion, i).size(), 1u);
    EXPECT_EQ(cv::norm(pan.render_frame(motion, i), pan.render(motion.R_neutral_from_camera[i], i),
                       cv::NORM_INF),
              0.0);
  }
}

// A 20 ms exposure at the pan's fastest frame: the views at the pan's rotations around the
// frame's, consecutive ones within a pixel, smear the marks; a pan that hardly moves is one view
// per exposure.
TEST(PhotoPan, AnExposureBlursAlongThePanAroundTheFramesRotation) {
  PanMotionOptions options;
  options.frames = 60;
  const PanMotion motion = make_pan_motion(options);
  ImagingOptions imaging;
  imaging.exposure_ms = 20.0;
  imaging.max_exposure_samples = 15;
  const PhotoPan sharp(marked_photo(), kPhoto, kCamera, 0.0, 1);
  const PhotoPan blurred(marked_photo(), kPhoto, kCamera, 0.0, 1, imaging);
  int fastest = 1, slowest = 1;
  auto step = [&](int i) {
    return rotation_step_deg(motion.R_neutral_from_camera[i - 1], motion.R_neutral_from_camera[i]);
  };
  for (int i = 1; i < options.frames; ++i) {
    if (step(i) > step(fastest)) fastest = i;
    if (step(i) < step(slowest)) slowest = i;
  }
  const std::vector<Eigen::Matrix3d> rotations = blurred.exposure_rotations(motion, fastest);
  const size_t n = rotations.size();
  ASSERT_EQ(n % 2, 1u);
  EXPECT_EQ(rotations[n / 2], motion.R_neutral_from_camera[fastest]);
  const double t = motion.times[fastest], half = 0.010 * (n - 1.0) / n;
  EXPECT_LT(rotation_step_deg(rotations.front(), motion.R_neutral_from_camera_at(t - half)), 1e-9);
  EXPECT_LT(rotation_step_deg(rotations.back(), motion.R_neutral_from_camera_at(t + half)), 1e-9);
  const double moved = pan_motion_px(kCamera, motion.R_neutral_from_camera_at(t - 0.010),
                                     motion.R_neutral_from_camera_at(t + 0.010));
  // About 1.3 deg per frame at 30 Hz: 0.78 deg in 20 ms, 7 pixels at f = 500.
  EXPECT_GT(moved, 5.0);
  EXPECT_GE(static_cast<double>(n), moved);
  const cv::Mat instant = sharp.render_frame(motion, fastest);
  const cv::Mat smeared = blurred.render_frame(motion, fastest);
  EXPECT_LT(gradient_energy(smeared), 0.6 * gradient_energy(instant));
  EXPECT_NEAR(cv::mean(smeared)[0], cv::mean(instant)[0], 0.5);

  // Slower where it turns back: fewer views.
  EXPECT_LT(blurred.exposure_rotations(motion, slowest).size(), n);

  // A pan too slow to move the image by a pixel in the exposure is not blurred.
  options.max_step_deg = 0.02;
  const PanMotion creeping = make_pan_motion(options);
  for (int i : {0, 30, 59}) {
    EXPECT_EQ(blurred.exposure_rotations(creeping, i).size(), 1u);
    EXPECT_EQ(cv::norm(blurred.render_frame(creeping, i), sharp.render_frame(creeping, i),
                       cv::NORM_INF),
              0.0);
  }
}

TEST(PhotoPan, ExposureGainAndVignettingReachThePan) {
  PanMotionOptions options;
  options.frames = 40;
  const PanMotion motion = make_pan_motion(options);
  ImagingOptions imaging;
  imaging.exposure_drift = 0.15;
  // Noise dithers the rounding of the dark background.
  const PhotoPan fixed(marked_photo(), kPhoto, kCamera, 2.0, 1);
  const PhotoPan drifting(marked_photo(), kPhoto, kCamera, 2.0, 1, imaging);
  for (int i : {0, 20, 39}) {
    const double ratio =
        cv::mean(drifting.render_frame(motion, i))[0] / cv::mean(fixed.render_frame(motion, i))[0];
    EXPECT_NEAR(ratio, exposure_gain(0.15, 1, motion.times[i]), 0.01) << i;
  }
  imaging = ImagingOptions();
  imaging.vignetting = 0.35;
  const cv::Mat dark = PhotoPan(marked_photo(), kPhoto, kCamera, 0.0, 1, imaging)
                           .render(Eigen::Matrix3d::Identity(), 0);
  const cv::Mat plain = PhotoPan(marked_photo(), kPhoto, kCamera, 0.0, 1)
                            .render(Eigen::Matrix3d::Identity(), 0);
  // The photograph's dark background is 20 grey levels: 13 in the corners.
  EXPECT_NEAR(dark.at<uchar>(0, 0), 0.65 * plain.at<uchar>(0, 0), 1.0);
  EXPECT_EQ(dark.at<uchar>(120, 160), plain.at<uchar>(120, 160));
  imaging.vignetting = 1.0;
  EXPECT_THROW(PhotoPan(marked_photo(), kPhoto, kCamera, 0.0, 1, imaging), std::invalid_argument);
}

TEST(PhotoPan, ViewsLeavingThePhotographAreFound) {
  Eigen::Vector2d outside;
  EXPECT_TRUE(view_inside_photo(pan_homography(kPhoto, kCamera, pan_rotation(8, 3, 2)), kCamera,
                                kPhoto, 1.0, &outside));
  EXPECT_FALSE(view_inside_photo(pan_homography(kPhoto, kCamera, pan_rotation(15, 0, 0)), kCamera,
                                 kPhoto, 1.0, &outside));
  EXPECT_GT(outside.x(), kPhoto.width - 2.0);
  EXPECT_FALSE(view_inside_photo(pan_homography(kPhoto, kCamera, pan_rotation(0, -9, 0)), kCamera,
                                 kPhoto, 1.0, &outside));
  EXPECT_GT(outside.y(), kPhoto.height - 2.0);
  // Turned away: behind the photograph camera.
  EXPECT_FALSE(view_inside_photo(pan_homography(kPhoto, kCamera, pan_rotation(150, 0, 0)), kCamera,
                                 kPhoto, 1.0, &outside));
  EXPECT_TRUE(std::isnan(outside.x()));
  const cv::Mat& photo = marked_photo();
  EXPECT_THROW(PhotoPan(photo(cv::Rect(0, 0, 100, 100)).clone(), kPhoto, kCamera, 1.0, 1),
               std::invalid_argument);
  EXPECT_THROW(PhotoPan(photo, kPhoto, kCamera, -1.0, 1), std::invalid_argument);
  cv::Mat colour;
  cv::cvtColor(photo, colour, cv::COLOR_GRAY2BGR);
  EXPECT_THROW(PhotoPan(colour, kPhoto, kCamera, 1.0, 1), std::invalid_argument);
}

// ------------------------------------------------------------------------------------------------
// The motion

TEST(PanMotion, RotationAxesAreTheCamerasAsDocumented) {
  EXPECT_GT(pan_rotation(10, 0, 0).col(2).x(), 0.17);   // yaw: looks right
  EXPECT_LT(pan_rotation(0, 10, 0).col(2).y(), -0.17);  // pitch: looks up (y is down)
  EXPECT_GT(pan_rotation(0, 0, 10).col(0).y(), 0.17);   // roll: x turns towards y (clockwise)
  EXPECT_NEAR(rotation_step_deg(pan_rotation(3, 0, 0), pan_rotation(-2, 0, 0)), 5.0, 1e-12);
}

TEST(PanMotion, KeepsItsAmplitudesAndItsLargestStepAndReversesSlowly) {
  for (uint64_t seed : {1, 2, 3, 4, 5}) {
    PanMotionOptions o;
    o.seed = seed;
    const PanMotion pan = make_pan_motion(o);
    ASSERT_EQ(pan.R_neutral_from_camera.size(), 300u);
    EXPECT_NEAR(pan.times.back(), 299.0 / 30.0, 1e-12);
    Eigen::Vector3d peak = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& a : pan.yaw_pitch_roll_deg) peak = peak.cwiseMax(a.cwiseAbs());
    EXPECT_LE(peak.x(), 8.0 + 1e-12);
    EXPECT_LE(peak.y(), 3.0 + 1e-12);
    EXPECT_LE(peak.z(), 2.0 + 1e-12);
    EXPECT_GT(peak.x(), 8.0 - 0.05);  // reached, but for the peak between two frames
    EXPECT_GT(peak.y(), 3.0 - 0.05);
    EXPECT_GT(peak.z(), 2.0 - 0.05);
    std::vector<double> steps;
    for (size_t i = 1; i < pan.R_neutral_from_camera.size(); ++i) {
      const Eigen::Vector3d& a = pan.yaw_pitch_roll_deg[i];
      EXPECT_LT((pan.R_neutral_from_camera[i] - pan_rotation(a.x(), a.y(), a.z())).norm(), 1e-12);
      steps.push_back(
          rotation_step_deg(pan.R_neutral_from_camera[i - 1], pan.R_neutral_from_camera[i]));
    }
    const double fastest = *std::max_element(steps.begin(), steps.end());
    EXPECT_LE(fastest, 1.3);
    EXPECT_GE(fastest, 0.99 * 1.3);  // reaches it
    EXPECT_DOUBLE_EQ(fastest, pan.max_step_deg);
    EXPECT_DOUBLE_EQ(*std::min_element(steps.begin(), steps.end()), pan.min_step_deg);
    // Where the yaw reverses the camera turns slowly: a VO sees little motion there.
    int reversals = 0;
    std::vector<double> at_reversals;
    for (size_t i = 1; i + 1 < pan.yaw_pitch_roll_deg.size(); ++i) {
      const double before = pan.yaw_pitch_roll_deg[i].x() - pan.yaw_pitch_roll_deg[i - 1].x();
      const double after = pan.yaw_pitch_roll_deg[i + 1].x() - pan.yaw_pitch_roll_deg[i].x();
      if (before * after < 0.0) {
        ++reversals;
        at_reversals.push_back(std::min(steps[i - 1], steps[i]));
      }
    }
    EXPECT_GE(reversals, 4) << "seed " << seed;
    EXPECT_LT(*std::max_element(at_reversals.begin(), at_reversals.end()), 0.35 * 1.3)
        << "seed " << seed;
    EXPECT_LT(pan.min_step_deg, 0.1 * 1.3) << "seed " << seed;
    const size_t fast =
        std::count_if(steps.begin(), steps.end(), [](double s) { return s > 0.8 * 1.3; });
    EXPECT_GT(fast, 10u) << "seed " << seed;
  }
}

TEST(PanMotion, SeedsAndOptionsChangeIt) {
  PanMotionOptions o;
  const PanMotion a = make_pan_motion(o), same = make_pan_motion(o);
  o.seed = 9;
  const PanMotion other = make_pan_motion(o);
  EXPECT_EQ(a.yaw_pitch_roll_deg, same.yaw_pitch_roll_deg);
  EXPECT_NE(a.yaw_pitch_roll_deg, other.yaw_pitch_roll_deg);
  PanMotionOptions yaw_only;
  yaw_only.yaw_deg = 4.0;
  yaw_only.pitch_deg = yaw_only.roll_deg = 0.0;
  yaw_only.max_step_deg = 0.5;
  yaw_only.frames = 120;
  const PanMotion pan = make_pan_motion(yaw_only);
  EXPECT_EQ(pan.R_neutral_from_camera.size(), 120u);
  EXPECT_LE(pan.max_step_deg, 0.5);
  EXPECT_GE(pan.max_step_deg, 0.5 - 1e-6);
  // Short sequences reach the largest step too.
  for (int frames : {3, 10, 20, 50, 1000}) {
    PanMotionOptions short_pan;
    short_pan.frames = frames;
    const PanMotion p = make_pan_motion(short_pan);
    EXPECT_LE(p.max_step_deg, 1.3) << frames << " frames";
    EXPECT_GE(p.max_step_deg, 1.3 - 1e-6) << frames << " frames";
  }
  // Amplitudes too small for the step: the fastest swing allowed, below the limit.
  PanMotionOptions tiny;
  tiny.yaw_deg = 0.05;
  tiny.pitch_deg = tiny.roll_deg = 0.0;
  const PanMotion small = make_pan_motion(tiny);
  EXPECT_LT(small.max_step_deg, 0.1);
  EXPECT_GT(small.max_step_deg, 0.01);
  for (const Eigen::Vector3d& angles : pan.yaw_pitch_roll_deg) {
    EXPECT_LE(std::abs(angles.x()), 4.0 + 1e-12);
    EXPECT_EQ(angles.y(), 0.0);
    EXPECT_EQ(angles.z(), 0.0);
  }
  auto with = [](auto change) {
    PanMotionOptions bad;
    change(bad);
    return bad;
  };
  for (const PanMotionOptions& bad :
       {with([](PanMotionOptions& p) { p.frames = 1; }),
        with([](PanMotionOptions& p) { p.rate = 0.0; }),
        with([](PanMotionOptions& p) { p.yaw_deg = std::nan(""); }),
        with([](PanMotionOptions& p) { p.pitch_deg = -1.0; }),
        with([](PanMotionOptions& p) { p.roll_deg = 50.0; }),
        with([](PanMotionOptions& p) { p.max_step_deg = 0.0; }),
        with([](PanMotionOptions& p) { p.max_step_deg = HUGE_VAL; }),
        with([](PanMotionOptions& p) { p.yaw_deg = p.pitch_deg = p.roll_deg = 0.0; })})
    EXPECT_THROW(make_pan_motion(bad), std::invalid_argument);
}

TEST(PanMotion, ThePanBetweenTheFramesPassesThroughThem) {
  PanMotionOptions options;
  options.frames = 50;
  const PanMotion pan = make_pan_motion(options);
  for (int i = 0; i < options.frames; ++i) {
    EXPECT_EQ(pan.yaw_pitch_roll_deg_at(pan.times[i]), pan.yaw_pitch_roll_deg[i]) << i;
    EXPECT_EQ(pan.R_neutral_from_camera_at(pan.times[i]), pan.R_neutral_from_camera[i]) << i;
  }
  // Half way between two frames it is half way, near enough (the pan is smooth).
  for (int i = 1; i < options.frames; ++i) {
    const Eigen::Matrix3d middle = pan.R_neutral_from_camera_at(0.5 * (pan.times[i - 1] +
                                                                        pan.times[i]));
    const double step = rotation_step_deg(pan.R_neutral_from_camera[i - 1],
                                          pan.R_neutral_from_camera[i]);
    EXPECT_NEAR(rotation_step_deg(pan.R_neutral_from_camera[i - 1], middle), 0.5 * step, 0.05);
  }
}

TEST(PanMotion, DropEveryLeavesOutEveryNthFrame) {
  for (int i = 0; i < 50; ++i) EXPECT_FALSE(is_dropped(i, 0));
  std::vector<int> dropped;
  for (int i = 0; i < 12; ++i)
    if (is_dropped(i, 3)) dropped.push_back(i);
  EXPECT_EQ(dropped, (std::vector<int>{2, 5, 8, 11}));
  for (int n : {2, 5, 7}) {
    EXPECT_FALSE(is_dropped(0, n));  // the first frame, the ground truth's world, stays
    int kept = 0;
    for (int i = 0; i < 300; ++i) kept += !is_dropped(i, n);
    EXPECT_EQ(kept, 300 - 300 / n);
  }
}

// What hybrid_vo_render_pan writes, read back by the KITTI reader: the first frame's camera is
// the world, every centre 0, the relative rotations and the true stamps of the frames kept.
TEST(PanMotion, PosesRoundTripThroughTheKittiLayout) {
  PanMotionOptions o;
  o.frames = 40;
  const PanMotion pan = make_pan_motion(o);
  const cv::Mat& photo = marked_photo();
  const PhotoPan renderer(photo, kPhoto, kCamera, 1.0, 1);
  TempDir dir;
  datasets::KittiWriter writer;
  std::string error;
  ASSERT_TRUE(writer.open(dir.path().string(), "pan", kCamera, 0.0, &error)) << error;
  std::vector<int> kept;
  for (int i = 0; i < o.frames; ++i) {
    if (is_dropped(i, 4)) continue;
    kept.push_back(i);
    ASSERT_TRUE(writer.add_frame(pan.times[i], renderer.render(pan.R_neutral_from_camera[i], i),
                                 cv::Mat(), pan.R_first_from_camera(i), Eigen::Vector3d::Zero(),
                                 &error))
        << error;
  }
  ASSERT_TRUE(writer.close(&error)) << error;
  datasets::Sequence sequence;
  ASSERT_TRUE(datasets::read_kitti(writer.sequence_dir(), &sequence, &error)) << error;
  ASSERT_EQ(sequence.size(), 30);
  EXPECT_DOUBLE_EQ(sequence.frames[0].camera.pinhole.fx, kCamera.fx);
  EXPECT_DOUBLE_EQ(sequence.frames[0].camera.pinhole.cx, kCamera.cx);
  EXPECT_EQ(sequence.frames[0].camera.pinhole.width, kCamera.width);
  EXPECT_LT((sequence.frames[0].R_wc - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  for (int k = 0; k < sequence.size(); ++k) {
    const int i = kept[k];
    EXPECT_NEAR(sequence.frames[k].timestamp, i / 30.0, 1e-6) << "frame " << i;
    EXPECT_EQ(sequence.frames[k].c_w, Eigen::Vector3d::Zero());
    EXPECT_LT((sequence.frames[k].R_wc - pan.R_first_from_camera(i)).norm(), 1e-10);
    if (k == 0) continue;
    const RelativePose step = datasets::relative_pose(sequence, k - 1, k);
    EXPECT_NEAR(
        Eigen::AngleAxisd(step.R).angle() * 180.0 / 3.14159265358979323846,
        rotation_step_deg(pan.R_neutral_from_camera[kept[k - 1]], pan.R_neutral_from_camera[i]),
        1e-8);
  }
}

// ------------------------------------------------------------------------------------------------
// Options

TEST(PanOptions, ArgumentsAreParsedAndBadOnesRejected) {
  PanOptions o;
  EXPECT_EQ(parse_pan_args({"--photo", "p.jpg", "--kitti-dir", "/tmp/k"}, &o), "");
  EXPECT_EQ(o.photo, "p.jpg");
  EXPECT_TRUE(o.camera_file.empty());
  EXPECT_FALSE(o.has_photo_K);
  EXPECT_EQ(o.motion.frames, 300);
  EXPECT_EQ(o.motion.rate, 30.0);
  EXPECT_EQ(o.motion.max_step_deg, 1.3);
  EXPECT_EQ(o.drop_every, 0);
  const PinholeCamera camera = pan_camera(o);
  EXPECT_EQ(camera.fx, 1000.0);
  EXPECT_EQ(camera.cx, 319.5);
  EXPECT_EQ(camera.cy, 239.5);
  EXPECT_EQ(camera.width, 640);

  PanOptions all;
  EXPECT_EQ(parse_pan_args({"--photo",
                            "p.jpg",
                            "--out",
                            "x.bag",
                            "--K",
                            "2759.5,2764.2,1520.7,1006.8",
                            "--width",
                            "320",
                            "--height",
                            "240",
                            "--focal",
                            "500",
                            "--frames",
                            "90",
                            "--rate",
                            "15",
                            "--seed",
                            "3",
                            "--yaw-deg",
                            "5",
                            "--pitch-deg",
                            "0",
                            "--roll-deg",
                            "1",
                            "--max-step-deg",
                            "0.8",
                            "--drop-every",
                            "4",
                            "--noise",
                            "2",
                            "--kitti-dir",
                            "/tmp/k",
                            "--kitti-name",
                            "fountain"},
                           &all),
            "");
  EXPECT_TRUE(all.has_photo_K);
  EXPECT_EQ(all.photo_K.fx, 2759.5);
  EXPECT_EQ(all.photo_K.cy, 1006.8);
  EXPECT_EQ(all.focal, 500.0);
  EXPECT_EQ(all.motion.frames, 90);
  EXPECT_EQ(all.motion.rate, 15.0);
  EXPECT_EQ(all.motion.seed, 3u);
  EXPECT_EQ(all.motion.yaw_deg, 5.0);
  EXPECT_EQ(all.motion.pitch_deg, 0.0);
  EXPECT_EQ(all.motion.max_step_deg, 0.8);
  EXPECT_EQ(all.drop_every, 4);
  EXPECT_EQ(all.kitti_name, "fountain");

  const std::vector<std::pair<std::vector<std::string>, std::string>> bad = {
      {{"--kitti-dir", "/tmp/k"}, "--photo"},
      {{"--photo", "p.jpg"}, "--out OUT.bag or --kitti-dir"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--K", "1,2,3"}, "--K"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--K", "nan,1,1,1"}, "--K"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--K", "0,1,1,1"}, "--K"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--K", "1,1,1,1,"}, "--K"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--K", "1,1,1,1", "--camera", "c"},
       "exclude each other"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--yaw-deg", "-1"}, "--yaw-deg"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--roll-deg", "inf"}, "--roll-deg"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--max-step-deg", "0"}, "--max-step-deg"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--drop-every", "1"}, "--drop-every"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--frames", "1"}, "--frames"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--focal", "0"}, "--focal"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--kitti-name", "a/b"}, "--kitti-name"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--yaw-deg", "0", "--pitch-deg", "0",
        "--roll-deg", "0"},
       "no pan"},
      {{"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--bogus"}, "--bogus"},
      {{"--photo"}, "needs a value"},
  };
  for (const auto& [args, message] : bad) {
    PanOptions options;
    const std::string error = parse_pan_args(args, &options);
    EXPECT_TRUE(contains(error, message)) << error;
  }
  PanOptions help;
  EXPECT_EQ(parse_pan_args({"--help"}, &help), "");
  EXPECT_TRUE(help.help);

  // The imaging options, as hybrid_vo_render_sequence's.
  PanOptions realistic;
  ASSERT_EQ(parse_pan_args({"--photo", "p.jpg", "--kitti-dir", "/tmp/k", "--imaging", "realistic",
                            "--jpeg-artefacts", "60"},
                           &realistic),
            "");
  EXPECT_EQ(realistic.imaging.exposure_ms, 10.0);
  EXPECT_EQ(realistic.imaging.vignetting, 0.35);
  EXPECT_EQ(realistic.imaging.jpeg_quality, 60);
  EXPECT_EQ(realistic.noise, kRealisticReadNoise);
  PanOptions clean;
  ASSERT_EQ(parse_pan_args({"--photo", "p.jpg", "--kitti-dir", "/tmp/k"}, &clean), "");
  EXPECT_EQ(describe(clean.imaging), "clean");
  EXPECT_EQ(clean.noise, 1.0);
  PanOptions slow;
  EXPECT_TRUE(contains(parse_pan_args({"--photo", "p.jpg", "--kitti-dir", "/tmp/k",
                                       "--exposure-ms", "40"},
                                      &slow),
                       "--exposure-ms 40 is longer than a frame at 30 Hz"));
  EXPECT_TRUE(contains(parse_pan_args({"--photo", "p.jpg", "--kitti-dir", "/tmp/k",
                                       "--vignetting", "-0.1"},
                                      &slow),
                       "bad value '-0.1' for --vignetting"));
  EXPECT_TRUE(contains(pan_usage("pan"), "--imaging clean|realistic"));
  EXPECT_TRUE(contains(pan_usage("pan"), "--jpeg-artefacts"));
}

}  // namespace
