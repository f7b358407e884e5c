// The realistic imaging of the renderer (render/imaging.h, render_exposure, and the sequence's
// exposures): clean stays as it was; the noise, vignetting, motion blur, auto exposure and JPEG
// do what they are set to; the ground truth does not move.

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/render/imaging.h"
#include "hybrid_vo/render/sequence.h"

namespace {

using namespace hybrid_vo;
using namespace hybrid_vo::render;

constexpr double kPi = 3.14159265358979323846;

bool same_pose(const CameraPose& a, const CameraPose& b) {
  return a.R_world_from_camera == b.R_world_from_camera && a.centre == b.centre;
}

// A small sequence (320 x 240, supersampling 2) for the tests that render.
SequenceOptions small_sequence(Motion motion = Motion::kWalk) {
  SequenceOptions o;
  o.kitti_dir = "unused";
  o.width = 320;
  o.height = 240;
  o.supersampling = 2;
  o.frames = 60;
  o.rate = 30.0;
  o.motion = motion;
  return o;
}

cv::Mat as_float(const cv::Mat& image) {
  cv::Mat f;
  image.convertTo(f, CV_32F);
  return f;
}

// The image blurred by a horizontal box of width w pixels (a continuous box, sampled).
cv::Mat box_blurred(const cv::Mat& image, double w) {
  if (w < 1e-6) return image.clone();
  const int half = static_cast<int>(std::ceil(0.5 * w + 0.5));
  cv::Mat kernel(1, 2 * half + 1, CV_32F);
  for (int j = -half; j <= half; ++j) {
    const double overlap = std::min(j + 0.5, 0.5 * w) - std::max(j - 0.5, -0.5 * w);
    kernel.at<float>(0, j + half) = static_cast<float>(std::max(0.0, overlap) / w);
  }
  cv::Mat out;
  cv::filter2D(image, out, CV_32F, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  return out;
}

// The horizontal box width that best turns `sharp` into `blurred` within `roi`.
double fitted_box_width(const cv::Mat& sharp, const cv::Mat& blurred, const cv::Rect& roi) {
  double best_w = 0.0, best = std::numeric_limits<double>::infinity();
  for (double w = 0.0; w <= 16.0; w += 0.1) {
    const double error = cv::norm(box_blurred(sharp, w)(roi), blurred(roi), cv::NORM_L2SQR);
    if (error < best) {
      best = error;
      best_w = w;
    }
  }
  return best_w;
}

TEST(Imaging, CleanIsTheRenderersSensorAsItWas) {
  const ImagingOptions clean;
  EXPECT_EQ(clean.exposure_ms, 0.0);
  EXPECT_EQ(clean.vignetting, 0.0);
  EXPECT_EQ(clean.shot_noise_gain, 0.0);
  EXPECT_EQ(clean.exposure_drift, 0.0);
  EXPECT_EQ(clean.jpeg_quality, 0);
  EXPECT_EQ(describe(clean), "clean");
  EXPECT_EQ(exposure_gain(0.0, 5, 12.3), 1.0);

  // The sensor with the clean options: the optics' blur, Gaussian noise, rounding, as always.
  cv::Mat radiance(120, 160, CV_32FC1);
  cv::randu(radiance, 0.0, 260.0);
  RenderOptions o;
  o.noise_seed = 42;
  cv::Mat expected = radiance.clone();
  cv::GaussianBlur(expected, expected, cv::Size(0, 0), 0.5, 0.5, cv::BORDER_REFLECT);
  cv::Mat noise(expected.size(), CV_32FC1);
  cv::RNG rng(42 * 0x9E3779B97F4A7C15ull + 1);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  expected += noise;
  expected.convertTo(expected, CV_8U);
  EXPECT_EQ(cv::norm(sensor_image(radiance.clone(), o), expected, cv::NORM_INF), 0.0);

  // A clean sequence's frame is one instant's view; --imaging clean is the default.
  SequenceOptions options = small_sequence();
  options.frames = 3;
  SequenceOptions parsed = options;
  ASSERT_EQ(parse_sequence_args({"--kitti-dir", "unused", "--imaging", "clean"}, &parsed), "");
  EXPECT_EQ(parsed.noise, 1.0);
  EXPECT_EQ(describe(parsed.imaging), "clean");
  const Sequence seq = make_sequence(options);
  ASSERT_EQ(exposure_poses(seq, 2).size(), 1u);
  EXPECT_TRUE(same_pose(exposure_poses(seq, 2)[0], frame_pose(seq, 2)));
  RenderOptions view_options = seq.render;
  view_options.noise_sigma = 0.0;
  EXPECT_EQ(cv::norm(render_exposure(seq.scene, seq.lens, {frame_pose(seq, 2)}, view_options).image,
                     render_view(seq.scene, seq.camera, frame_pose(seq, 2), view_options).image,
                     cv::NORM_INF),
            0.0);
}

TEST(Imaging, NoiseVarianceGrowsWithTheSignalAsModelled) {
  for (double level : {20.0, 60.0, 120.0, 200.0}) {
    RenderOptions o;
    o.noise_sigma = kRealisticReadNoise;
    o.shot_noise_gain = 0.05;
    o.noise_seed = 3;
    const cv::Mat image = sensor_image(cv::Mat(300, 300, CV_32FC1, cv::Scalar(level)), o);
    cv::Scalar mean, stddev;
    cv::meanStdDev(image, mean, stddev);
    // Rounding adds 1/12 of a grey level squared.
    const double expected = o.noise_sigma * o.noise_sigma + o.shot_noise_gain * level + 1.0 / 12;
    EXPECT_NEAR(stddev[0] * stddev[0], expected, 0.04 * expected) << "level " << level;
    EXPECT_NEAR(mean[0], level, 0.05) << "level " << level;
    // The clean sensor's noise does not depend on the signal.
    RenderOptions clean;
    clean.noise_seed = 3;
    cv::meanStdDev(sensor_image(cv::Mat(300, 300, CV_32FC1, cv::Scalar(level)), clean), mean,
                   stddev);
    EXPECT_NEAR(stddev[0] * stddev[0], 1.0 + 1.0 / 12, 0.05) << "level " << level;
  }
}

TEST(Imaging, VignettingDarkensTheCornersByTheSetFraction) {
  RenderOptions o;
  o.blur_sigma = 0.0;
  o.noise_sigma = 0.0;
  o.vignetting = 0.35;
  const cv::Mat image = sensor_image(cv::Mat(480, 640, CV_32FC1, cv::Scalar(200.0)), o);
  for (const cv::Point& corner : {cv::Point(0, 0), cv::Point(639, 0), cv::Point(0, 479),
                                  cv::Point(639, 479)})
    EXPECT_NEAR(image.at<uchar>(corner), 200.0 * 0.65, 0.5);
  EXPECT_NEAR(image.at<uchar>(240, 320), 200.0, 0.5);
  EXPECT_NEAR(vignetting_factor(0.35, 0.0, 0.0, 640, 480), 0.65, 1e-12);
  EXPECT_EQ(vignetting_factor(0.35, 319.5, 239.5, 640, 480), 1.0);
  // Falling smoothly along the diagonal, cos^4-like: most of the darkening near the corners.
  double previous = 1.0;
  for (int k = 1; k <= 10; ++k) {
    const double r = 0.1 * k;
    const double f = vignetting_factor(0.35, 319.5 - r * 319.5, 239.5 - r * 239.5, 640, 480);
    EXPECT_LT(f, previous);
    previous = f;
  }
  EXPECT_GT(vignetting_factor(0.35, 319.5 - 0.5 * 319.5, 239.5 - 0.5 * 239.5, 640, 480), 0.88);
}

TEST(Imaging, MotionBlurSmearsByTheImageMotionAndNotAtRest) {
  // At rest one view is the exposure, and the image is the instant's.
  SequenceOptions rest = small_sequence(Motion::kRest);
  rest.frames = 4;
  rest.noise = 0.0;
  const Sequence still = make_sequence(rest);
  rest.imaging.exposure_ms = 20.0;
  const Sequence exposed = make_sequence(rest);
  EXPECT_EQ(exposure_poses(exposed, 3).size(), 1u);
  EXPECT_EQ(cv::norm(render_frame(exposed, 3).image, render_frame(still, 3).image, cv::NORM_INF),
            0.0);

  // Turning about the camera's own vertical at 60 deg/s, a 20 ms exposure sweeps the image's
  // centre by f * 60 deg/s * 20 ms sideways.
  SequenceOptions turn = small_sequence(Motion::kTurn);
  turn.lever_arm = 0.0;
  turn.turn_rate = 60.0;
  turn.noise = 0.0;
  const Sequence sharp = make_sequence(turn);
  turn.imaging.exposure_ms = 20.0;
  turn.imaging.max_exposure_samples = 15;
  const Sequence blurred = make_sequence(turn);
  const int frame = 45;  // 1.5 s: past the 1 s ramp
  const double sweep = blurred.camera.fx * 60.0 * kPi / 180.0 * 0.020;
  const std::vector<CameraPose> poses = exposure_poses(blurred, frame);
  const double moved = image_motion_px(blurred.scene, blurred.lens, poses.front(), poses.back());
  EXPECT_GE(static_cast<double>(poses.size()), sweep);  // consecutive views within a pixel
  EXPECT_EQ(poses.size() % 2, 1u);
  // The motion between the first and the last view, (n - 1) / n of the exposure, at the centre
  // and more towards the sides.
  const double first_to_last = sweep * (poses.size() - 1.0) / poses.size();
  EXPECT_GT(moved, first_to_last);
  EXPECT_LT(moved, 1.6 * first_to_last);
  const cv::Mat a = as_float(render_frame(sharp, frame).image);
  const cv::Mat b = as_float(render_frame(blurred, frame).image);
  const cv::Rect centre(100, 60, 120, 120);
  EXPECT_NEAR(fitted_box_width(a, b, centre), sweep, 0.15 * sweep) << "sweep " << sweep;
  EXPECT_NEAR(cv::mean(b(centre))[0], cv::mean(a(centre))[0], 1.0);
}

TEST(Imaging, ExposureGainStaysWithinItsBoundsWandersAndSteps) {
  const double drift = 0.15;
  double lowest = 2.0, highest = 0.0, previous = exposure_gain(drift, 1, 0.0);
  int steps = 0;
  for (int k = 1; k < 60000; ++k) {
    const double gain = exposure_gain(drift, 1, 0.01 * k);
    lowest = std::min(lowest, gain);
    highest = std::max(highest, gain);
    // The wander changes by at most 0.0036 in 10 ms; more is a step.
    if (std::abs(gain - previous) > 0.006) ++steps;
    previous = gain;
  }
  EXPECT_GE(lowest, 1.0 - drift);
  EXPECT_LE(highest, 1.0 + drift);
  EXPECT_LT(lowest, 1.0 - 0.5 * drift);
  EXPECT_GT(highest, 1.0 + 0.5 * drift);
  EXPECT_GT(steps, 60);   // about one every 4 s over 600 s
  EXPECT_LT(steps, 250);
  EXPECT_EQ(exposure_gain(drift, 1, 7.25), exposure_gain(drift, 1, 7.25));
  EXPECT_NE(exposure_gain(drift, 1, 7.25), exposure_gain(drift, 2, 7.25));

  // A frame's brightness follows its gain.
  SequenceOptions options = small_sequence(Motion::kRest);
  options.frames = 40;
  options.noise = 0.0;
  const Sequence fixed = make_sequence(options);
  options.imaging.exposure_drift = drift;
  const Sequence drifting = make_sequence(options);
  for (int frame : {0, 20, 39}) {
    const cv::Mat reference = render_frame(fixed, frame).image;
    // Away from black and from saturation.
    cv::Mat unclipped = (reference > 20) & (reference < 200);
    const double ratio = cv::mean(render_frame(drifting, frame).image, unclipped)[0] /
                         cv::mean(reference, unclipped)[0];
    EXPECT_NEAR(ratio, exposure_gain(drift, options.seed, frame / options.rate), 0.005);
  }
}

TEST(Imaging, JpegArtefactsChangePixelsButKeepTheMean) {
  SequenceOptions options = small_sequence();
  options.frames = 2;
  options.noise = 0.0;
  const Sequence seq = make_sequence(options);
  const cv::Mat radiance = as_float(render_frame(seq, 1).image);
  RenderOptions o;
  o.blur_sigma = 0.0;
  o.noise_sigma = 0.0;
  const cv::Mat plain = sensor_image(radiance.clone(), o);
  EXPECT_EQ(cv::norm(plain, render_frame(seq, 1).image, cv::NORM_INF), 0.0);
  double previous_change = 0.0;
  for (int quality : {95, 85, 40}) {
    o.jpeg_quality = quality;
    const cv::Mat coded = sensor_image(radiance.clone(), o);
    ASSERT_EQ(coded.type(), CV_8UC1);
    ASSERT_EQ(coded.size(), plain.size());
    cv::Mat changed;
    cv::compare(coded, plain, changed, cv::CMP_NE);
    EXPECT_GT(cv::countNonZero(changed), static_cast<int>(plain.total() / 5)) << quality;
    const double change = cv::norm(coded, plain, cv::NORM_L1) / plain.total();
    EXPECT_GT(change, previous_change) << quality;
    previous_change = change;
    EXPECT_NEAR(cv::mean(coded)[0], cv::mean(plain)[0], 0.3) << quality;
  }
}

TEST(Imaging, GroundTruthDoesNotChangeWithImaging) {
  SequenceOptions options = small_sequence();
  options.frames = 30;
  const Sequence clean = make_sequence(options);
  ASSERT_EQ(parse_sequence_args({"--kitti-dir", "unused", "--imaging", "realistic", "--frames",
                                 "30", "--width", "320", "--height", "240", "--rate", "30"},
                                &options),
            "");
  const Sequence realistic = make_sequence(options);
  for (int i = 0; i < 30; ++i) {
    EXPECT_TRUE(same_pose(clean.trajectory.poses[i], realistic.trajectory.poses[i])) << i;
    EXPECT_EQ(clean.trajectory.times[i], realistic.trajectory.times[i]);
    // The path between the frames passes through them, and an exposure is centred on its
    // frame's pose, symmetric about it.
    EXPECT_TRUE(same_pose(clean.trajectory.pose_at(clean.trajectory.times[i]),
                          clean.trajectory.poses[i]));
    const std::vector<CameraPose> poses = exposure_poses(realistic, i);
    ASSERT_EQ(poses.size() % 2, 1u);
    EXPECT_TRUE(same_pose(poses[poses.size() / 2], frame_pose(realistic, i)));
    const Eigen::Vector3d middle = 0.5 * (poses.front().centre + poses.back().centre);
    EXPECT_LT((middle - frame_pose(realistic, i).centre).norm(), 1e-4);
  }
  // The right camera's exposure is the left one's, shifted by the baseline.
  const std::vector<CameraPose> left = exposure_poses(realistic, 12);
  const std::vector<CameraPose> right = exposure_poses(realistic, 12, true);
  ASSERT_EQ(left.size(), right.size());
  for (size_t k = 0; k < left.size(); ++k)
    EXPECT_TRUE(same_pose(stereo_right(left[k], options.baseline), right[k]));
}

TEST(Imaging, ExposureSamplesAndOffsets) {
  EXPECT_EQ(exposure_samples(0.0, 7), 1);
  EXPECT_EQ(exposure_samples(0.99, 7), 1);
  EXPECT_EQ(exposure_samples(1.5, 7), 3);
  EXPECT_EQ(exposure_samples(3.0, 7), 3);
  EXPECT_EQ(exposure_samples(4.2, 7), 5);
  EXPECT_EQ(exposure_samples(40.0, 7), 7);
  EXPECT_EQ(exposure_samples(40.0, 1), 1);
  const std::vector<double> offsets = exposure_offsets(0.010, 5);
  ASSERT_EQ(offsets.size(), 5u);
  EXPECT_EQ(offsets[2], 0.0);
  EXPECT_NEAR(offsets[0], -0.004, 1e-15);
  EXPECT_NEAR(offsets[4], 0.004, 1e-15);
  EXPECT_EQ(exposure_offsets(0.010, 1), std::vector<double>{0.0});
}

TEST(ImagingOptions, ArgumentsAreParsedAndBadOnesRejected) {
  SequenceOptions realistic;
  ASSERT_EQ(parse_sequence_args({"--kitti-dir", "k", "--imaging", "realistic"}, &realistic), "");
  const ImagingOptions preset = realistic_imaging();
  EXPECT_EQ(realistic.imaging.exposure_ms, 10.0);
  EXPECT_EQ(realistic.imaging.vignetting, 0.35);
  EXPECT_EQ(realistic.imaging.shot_noise_gain, 0.05);
  EXPECT_EQ(realistic.imaging.exposure_drift, 0.15);
  EXPECT_EQ(realistic.imaging.jpeg_quality, 85);
  EXPECT_EQ(realistic.imaging.max_exposure_samples, preset.max_exposure_samples);
  EXPECT_EQ(realistic.noise, kRealisticReadNoise);

  // The knobs given replace the preset's, before or after it; --noise is the read noise.
  SequenceOptions tuned;
  ASSERT_EQ(parse_sequence_args({"--kitti-dir", "k", "--vignetting", "0.2", "--noise", "2",
                                 "--imaging", "realistic", "--jpeg-artefacts", "0",
                                 "--exposure-ms", "5", "--exposure-samples", "3",
                                 "--shot-noise-gain", "0.1", "--exposure-drift", "0.05"},
                                &tuned),
            "");
  EXPECT_EQ(tuned.imaging.vignetting, 0.2);
  EXPECT_EQ(tuned.noise, 2.0);
  EXPECT_EQ(tuned.imaging.jpeg_quality, 0);
  EXPECT_EQ(tuned.imaging.exposure_ms, 5.0);
  EXPECT_EQ(tuned.imaging.max_exposure_samples, 3);
  EXPECT_EQ(tuned.imaging.shot_noise_gain, 0.1);
  EXPECT_EQ(tuned.imaging.exposure_drift, 0.05);

  // One knob alone adds its effect to the clean imaging.
  SequenceOptions jpeg_only;
  ASSERT_EQ(parse_sequence_args({"--kitti-dir", "k", "--jpeg-artefacts", "70"}, &jpeg_only), "");
  EXPECT_EQ(jpeg_only.imaging.jpeg_quality, 70);
  EXPECT_EQ(jpeg_only.imaging.exposure_ms, 0.0);
  EXPECT_EQ(jpeg_only.noise, 1.0);
  EXPECT_EQ(describe(jpeg_only.imaging), "JPEG 70");

  const std::vector<std::pair<std::vector<std::string>, std::string>> bad = {
      {{"--imaging", "fancy"}, "bad value 'fancy' for --imaging"},
      {{"--imaging"}, "--imaging needs a value"},
      {{"--exposure-ms", "-1"}, "--exposure-ms"},
      {{"--exposure-ms", "nan"}, "--exposure-ms"},
      {{"--exposure-ms", "150"}, "--exposure-ms 150 is longer than a frame at 10 Hz (100 ms)"},
      {{"--exposure-ms", "40", "--rate", "30"}, "longer than a frame at 30 Hz"},
      {{"--exposure-samples", "4"}, "--exposure-samples"},
      {{"--exposure-samples", "0"}, "--exposure-samples"},
      {{"--vignetting", "1"}, "--vignetting"},
      {{"--shot-noise-gain", "-0.1"}, "--shot-noise-gain"},
      {{"--exposure-drift", "1"}, "--exposure-drift"},
      {{"--jpeg-artefacts", "101"}, "--jpeg-artefacts"},
      {{"--jpeg-artefacts", "8.5"}, "--jpeg-artefacts"},
  };
  for (const auto& [extra, message] : bad) {
    std::vector<std::string> args = {"--kitti-dir", "k"};
    args.insert(args.end(), extra.begin(), extra.end());
    SequenceOptions options;
    const std::string error = parse_sequence_args(args, &options);
    EXPECT_NE(error.find(message), std::string::npos) << "'" << error << "'";
  }
  const std::string usage = sequence_usage("render");
  for (const char* option : {"--imaging clean|realistic", "--exposure-ms", "--exposure-samples",
                             "--vignetting", "--noise", "--shot-noise-gain", "--exposure-drift",
                             "--jpeg-artefacts"})
    EXPECT_NE(usage.find(option), std::string::npos) << option;

  // Options set directly are checked too.
  SequenceOptions direct = small_sequence();
  direct.imaging.vignetting = 1.5;
  EXPECT_THROW(make_sequence(direct), std::invalid_argument);
  direct.imaging.vignetting = 0.0;
  direct.imaging.max_exposure_samples = 2;
  EXPECT_THROW(make_sequence(direct), std::invalid_argument);
  EXPECT_EQ(imaging_problem(realistic_imaging()), "");
}

}  // namespace
