// The trajectory tools the evaluation rests on: TUM files round trip, relative rotations follow
// the relative-pose convention, and drift and the rotation measures (per pair, over windows,
// orientation against the first frame) measure a known rotation bias.
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/evaluation/trajectory.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace evaluation {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d rotation(const Eigen::Vector3d& axis, double degrees) {
  return rotation_about(axis.normalized(), degrees * kDeg);
}

Trajectory random_trajectory(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    StampedPose p;
    p.stamp = 1000.0 + 0.1 * i;
    p.R = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
              .normalized()
              .toRotationMatrix();
    p.c = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * 10.0;
    t.push_back(p);
  }
  return t;
}

TEST(Trajectory, TumFileRoundTrip) {
  const Trajectory written = random_trajectory(20, 1);
  const std::string path = testing::TempDir() + "/trajectory_round_trip.txt";
  std::string error;
  ASSERT_TRUE(write_tum_trajectory(path, written, &error)) << error;
  Trajectory read;
  ASSERT_TRUE(read_tum_trajectory(path, &read, &error)) << error;
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    EXPECT_NEAR(read[i].stamp, written[i].stamp, 1e-6);
    EXPECT_LT((read[i].c - written[i].c).norm(), 1e-7);
    EXPECT_LT((read[i].R - written[i].R).norm(), 1e-7);
  }
}

TEST(Trajectory, WriteRejectsNonFinitePosesAndUnwritablePaths) {
  Trajectory t = random_trajectory(5, 2);
  t[3].c.y() = std::nan("");
  std::string error;
  EXPECT_FALSE(write_tum_trajectory(testing::TempDir() + "/trajectory_nan.txt", t, &error));
  EXPECT_NE(error.find("pose 3 is not finite"), std::string::npos) << error;
  error.clear();
  EXPECT_FALSE(write_tum_trajectory("/no/such/folder/trajectory.txt", random_trajectory(2, 3),
                                    &error));
  EXPECT_NE(error.find("cannot write"), std::string::npos) << error;
}

// relative_rotation(a, b) maps camera a's coordinates of a direction into camera b's.
TEST(Trajectory, RelativeRotationFollowsThePoseConvention) {
  const Trajectory t = random_trajectory(2, 4);
  const Eigen::Vector3d world(0.3, -1.2, 2.0);  // a direction in the world
  const Eigen::Vector3d in_a = t[0].R.transpose() * world, in_b = t[1].R.transpose() * world;
  EXPECT_LT((relative_rotation(t[0], t[1]) * in_a - in_b).norm(), 1e-12);
}

TEST(Trajectory, RotationDifferenceIsTheRotationVectorInDegrees) {
  const Eigen::Matrix3d b = rotation(Eigen::Vector3d(1, 2, 3), 40.0);
  for (const double degrees : {1e-4, 0.02, 3.0, 170.0}) {
    const Eigen::Vector3d axis = Eigen::Vector3d(-0.2, 1.0, 0.4).normalized();
    const Eigen::Vector3d w = rotation_difference_deg(rotation(axis, degrees) * b, b);
    EXPECT_LT((w - degrees * axis).norm(), 1e-9 * std::max(1.0, degrees)) << degrees;
  }
  EXPECT_LT(rotation_difference_deg(b, b).norm(), 1e-12);
}

// A camera on a straight 300 m path whose estimate turns 0.01 degrees per 5 m frame too many
// about its vertical axis: 0.2 degrees per 100 m of rotation drift; the truth against itself
// has none.
TEST(Trajectory, DriftMeasuresAConstantRotationBias) {
  Trajectory truth, estimate;
  for (int i = 0; i <= 60; ++i) {
    StampedPose g;
    g.stamp = 0.1 * i;
    g.c = Eigen::Vector3d(0.0, 0.0, 5.0 * i);
    truth.push_back(g);
    StampedPose e = g;
    e.R = rotation(Eigen::Vector3d::UnitY(), 0.01 * i);
    estimate.push_back(e);
  }
  const TrajectoryErrors same = compare_trajectories(truth, truth, false, 0.01);
  EXPECT_EQ(same.pairs, 60);
  EXPECT_GT(same.drift_segments, 0);
  EXPECT_NEAR(same.drift_rot_deg_per_100m, 0.0, 1e-9);
  EXPECT_NEAR(same.ate, 0.0, 1e-9);
  const TrajectoryErrors biased = compare_trajectories(estimate, truth, false, 0.01);
  EXPECT_NEAR(biased.drift_rot_deg_per_100m, 0.2, 1e-6);
  EXPECT_NEAR(biased.rpe_rot_deg, 0.01, 1e-9);
  for (const double e : biased.rot_err_deg) EXPECT_NEAR(e, 0.01, 1e-9);
}

// A hand-held camera at `rate` Hz turning about a tilted axis and moving forward, and an
// estimate of it whose rotation gains bias_deg(k) degrees about a fixed world axis by frame k
// (R_est_k = Q(bias_deg(k)) R_k): for every pair of frames i, j the relative rotation is then
// off by |bias_deg(j) - bias_deg(i)| exactly, whatever the camera's own rotation.
template <class Bias>
void biased_walk(int n, double rate, Bias bias_deg, Trajectory* truth, Trajectory* estimate) {
  const Eigen::Vector3d bias_axis = Eigen::Vector3d(0.3, 1.0, -0.2).normalized();
  for (int k = 0; k < n; ++k) {
    StampedPose g;
    g.stamp = 50.0 + k / rate;
    g.R = rotation(Eigen::Vector3d(0.1, 1.0, 0.3), 0.4 * k) * rotation(Eigen::Vector3d::UnitX(), 10.0);
    g.c = Eigen::Vector3d(0.02 * k, 0.01 * std::sin(0.3 * k), 0.05 * k);
    truth->push_back(g);
    StampedPose e = g;
    e.R = rotation(bias_axis, bias_deg(k)) * g.R;
    estimate->push_back(e);
  }
}

// A rotation bias of b degrees per frame at 25 Hz: b per pair, 25 b over 1 s, b (N - 1) at the
// last frame and at most; the truth against itself gives zeros.
TEST(Trajectory, RotationMeasuresOfAConstantBias) {
  const double b = 0.05;
  const int n = 100;
  Trajectory truth, estimate;
  biased_walk(n, 25.0, [&](int k) { return b * k; }, &truth, &estimate);
  const TrajectoryErrors e = compare_trajectories(estimate, truth, true, 1e-3);
  EXPECT_EQ(e.pairs, n - 1);
  EXPECT_NEAR(e.rot_pair_median_deg, b, 1e-9);
  EXPECT_EQ(e.window_s, 1.0);
  // Every pose up to 1 s before the last starts a window; so do the next two, whose windows end
  // at the last pose 1 and 2 frames short of a second (within 10 % of it).
  ASSERT_EQ(e.rot_window_err_deg.size(), static_cast<size_t>(n - 25 + 2));
  for (size_t i = 0; i < e.rot_window_err_deg.size(); ++i)
    EXPECT_NEAR(e.rot_window_err_deg[i], (i < n - 25 ? 25 : n - 1 - static_cast<int>(i)) * b,
                1e-9)
        << i;
  EXPECT_NEAR(e.rot_window_median_deg, 25 * b, 1e-9);
  EXPECT_NEAR(e.orientation_last_deg, (n - 1) * b, 1e-9);
  EXPECT_NEAR(e.orientation_max_deg, (n - 1) * b, 1e-9);
  // Rotations only: the centres agree, so the translation direction errors are the bias seen
  // from each camera, small but not zero.
  EXPECT_GT(e.dir_median_deg, 0.0);
  EXPECT_LT(e.dir_median_deg, 10.0);

  // Another window length: 0.6 s is 15 frames.
  const TrajectoryErrors short_window =
      compare_trajectories(estimate, truth, true, 1e-3, nullptr, 0.6);
  EXPECT_EQ(short_window.window_s, 0.6);
  EXPECT_EQ(short_window.rot_window_err_deg.size(), static_cast<size_t>(n - 15 + 1));
  EXPECT_NEAR(short_window.rot_window_median_deg, 15 * b, 1e-9);
  EXPECT_NEAR(short_window.rot_pair_median_deg, b, 1e-9);

  const TrajectoryErrors same = compare_trajectories(truth, truth, true, 1e-3);
  EXPECT_NEAR(same.rot_pair_median_deg, 0.0, 1e-9);
  EXPECT_NEAR(same.rot_window_median_deg, 0.0, 1e-9);
  EXPECT_NEAR(same.orientation_last_deg, 0.0, 1e-9);
  EXPECT_NEAR(same.orientation_max_deg, 0.0, 1e-9);
  EXPECT_NEAR(same.dir_median_deg, 0.0, 1e-6);
}

// A bias that grows for 40 frames and shrinks back for 20 (8 Hz): the orientation is worst at
// frame 40 (40 b), 20 b off at the end; over 1 s windows it is 8 b off, except where the window
// holds the turn of the bias.
TEST(Trajectory, OrientationErrorPeaksWhereTheBiasTurns) {
  const double b = 0.1;
  Trajectory truth, estimate;
  biased_walk(61, 8.0, [&](int k) { return k <= 40 ? b * k : b * (80 - k); }, &truth,
              &estimate);
  const TrajectoryErrors e = compare_trajectories(estimate, truth, true, 1e-3);
  EXPECT_NEAR(e.orientation_max_deg, 40 * b, 1e-9);
  EXPECT_NEAR(e.orientation_last_deg, 20 * b, 1e-9);
  EXPECT_NEAR(e.rot_pair_median_deg, b, 1e-9);
  ASSERT_EQ(e.rot_window_err_deg.size(), 53u);
  EXPECT_NEAR(e.rot_window_err_deg[0], 8 * b, 1e-9);
  EXPECT_NEAR(e.rot_window_err_deg[36], 0.0, 1e-9);  // 4 frames up, 4 down
  EXPECT_NEAR(e.rot_window_median_deg, 8 * b, 1e-9);
}

// The translation direction error per pair: an estimate that moves 10 degrees off the true
// direction (about the world z axis) in every frame.
TEST(Trajectory, DirectionErrorOfATurnedPath) {
  Trajectory truth, estimate;
  const Eigen::Matrix3d turn = rotation(Eigen::Vector3d::UnitZ(), 10.0);
  for (int k = 0; k < 20; ++k) {
    StampedPose g;
    g.stamp = 0.1 * k;
    g.R = rotation(Eigen::Vector3d(1.0, -0.5, 0.2), 30.0);
    g.c = Eigen::Vector3d(0.5 * k, 0.0, 0.0);
    truth.push_back(g);
    StampedPose e = g;
    e.c = turn * g.c;
    estimate.push_back(e);
  }
  const TrajectoryErrors e = compare_trajectories(estimate, truth, true, 1e-3);
  EXPECT_NEAR(e.dir_median_deg, 10.0, 1e-9);
  EXPECT_NEAR(e.rot_pair_median_deg, 0.0, 1e-9);
}

// Too short for a window, too few poses, a bad window length and poses that are not finite.
TEST(Trajectory, RotationMeasuresEdgeCases) {
  const double b = 0.05;
  Trajectory truth, estimate;
  biased_walk(20, 25.0, [&](int k) { return b * k; }, &truth, &estimate);  // 0.76 s
  const TrajectoryErrors short_run = compare_trajectories(estimate, truth, true, 1e-3);
  EXPECT_TRUE(short_run.rot_window_err_deg.empty());
  EXPECT_TRUE(std::isnan(short_run.rot_window_median_deg));
  EXPECT_NEAR(short_run.rot_pair_median_deg, b, 1e-9);
  EXPECT_NEAR(short_run.orientation_last_deg, 19 * b, 1e-9);
  // 10 Hz, the last pose 0.88 s after the first: more than 10 % short of 1 s, no window; at
  // 0.92 s it ends the first one.
  Trajectory t10, e10;
  biased_walk(11, 10.0, [&](int k) { return b * k; }, &t10, &e10);
  t10.back().stamp = e10.back().stamp = t10[0].stamp + 0.88;
  EXPECT_TRUE(compare_trajectories(e10, t10, true, 1e-3).rot_window_err_deg.empty());
  t10.back().stamp = e10.back().stamp = t10[0].stamp + 0.92;
  const TrajectoryErrors one_window = compare_trajectories(e10, t10, true, 1e-3);
  ASSERT_EQ(one_window.rot_window_err_deg.size(), 1u);
  EXPECT_NEAR(one_window.rot_window_err_deg[0], 10 * b, 1e-9);

  const std::vector<PosePair> poses = match_poses(estimate, truth, 1e-3);
  ASSERT_EQ(poses.size(), 20u);
  for (const double window : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()})
    EXPECT_TRUE(window_rotation_errors_deg(poses, window).empty()) << window;

  const TrajectoryErrors one = compare_trajectories({estimate[0]}, truth, true, 1e-3);
  EXPECT_EQ(one.pairs, 0);
  EXPECT_TRUE(std::isnan(one.rot_pair_median_deg));
  EXPECT_TRUE(std::isnan(one.dir_median_deg));
  EXPECT_TRUE(std::isnan(one.rot_window_median_deg));
  EXPECT_TRUE(std::isnan(one.orientation_last_deg));
  EXPECT_TRUE(std::isnan(one.orientation_max_deg));

  // A pose that is not finite, in the estimate or in the truth, is left out; the measures stay
  // finite and those that do not depend on it unchanged.
  Trajectory long_truth, long_estimate;
  biased_walk(100, 25.0, [&](int k) { return b * k; }, &long_truth, &long_estimate);
  long_estimate[40].R(0, 1) = std::nan("");
  long_truth[60].c.z() = std::nan("");
  EXPECT_EQ(match_poses(long_estimate, long_truth, 1e-3).size(), 98u);
  const TrajectoryErrors holes = compare_trajectories(long_estimate, long_truth, true, 1e-3);
  EXPECT_EQ(holes.pairs, 97);
  EXPECT_NEAR(holes.rot_pair_median_deg, b, 1e-9);
  EXPECT_NEAR(holes.rot_window_median_deg, 25 * b, 1e-9);
  EXPECT_NEAR(holes.orientation_last_deg, 99 * b, 1e-9);
  EXPECT_NEAR(holes.orientation_max_deg, 99 * b, 1e-9);
  EXPECT_TRUE(std::isfinite(holes.dir_median_deg));
  EXPECT_TRUE(std::isfinite(holes.ate));
}

Eigen::Matrix3d exp_deg(const Eigen::Vector3d& w_deg) {
  return w_deg.norm() > 0.0 ? rotation(w_deg, w_deg.norm()) : Eigen::Matrix3d::Identity();
}

// A reference that turns 0.74 % more than the camera and whose frame is rotated by 0.36 deg
// (about x) against it, on car-like motions (yaw of 3-10 deg, a little pitch and roll), with
// 0.003 deg of noise on the measured rotations and a tenth of them failed: the fit recovers both
// numbers.
TEST(Trajectory, RotationOffsetFitRecoversScaleAndTilt) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> yaw(3.0, 10.0), small(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.003);
  const double scale = 0.0074;
  const Eigen::Vector3d tilt(0.36, -0.08, 0.02);
  const Eigen::Matrix3d Q = exp_deg(tilt);
  std::vector<Eigen::Matrix3d> reference, measured;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d theta(small(rng), -yaw(rng), small(rng));
    reference.push_back(Q * exp_deg((1.0 + scale) * theta) * Q.transpose());
    // Every tenth measurement failed (3 deg off): outliers, not part of the offset.
    const Eigen::Vector3d error = i % 10 == 0 ? Eigen::Vector3d(2.0, -1.0, 2.0)
                                              : Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    measured.push_back(exp_deg(error) * exp_deg(theta));
  }
  const RotationOffsetFit fit = fit_rotation_offset(reference, measured);
  ASSERT_TRUE(fit.ok);
  EXPECT_LE(fit.pairs, 180);
  EXPECT_GE(fit.pairs, 150);
  EXPECT_NEAR(fit.scale, scale, 0.0005);
  // Only the tilt about axes across the motion is well observed; yaw is about y.
  EXPECT_NEAR(fit.tilt_deg.x(), tilt.x(), 0.03);
  EXPECT_NEAR(fit.tilt_deg.z(), tilt.z(), 0.03);
  EXPECT_NEAR(fit.tilt_deg.y(), tilt.y(), 0.3);
  EXPECT_GT(fit.rms_before_deg, 0.015);
  EXPECT_LT(fit.rms_after_deg, 0.006);

  // The same rotations as their own reference: nothing to fit.
  const RotationOffsetFit same = fit_rotation_offset(reference, reference);
  ASSERT_TRUE(same.ok);
  EXPECT_NEAR(same.scale, 0.0, 1e-9);
  EXPECT_LT(same.tilt_deg.norm(), 1e-6);
  EXPECT_LT(same.rms_before_deg, 1e-9);
}

TEST(Trajectory, RotationOffsetFitRefusesWhatItCannotTell) {
  std::vector<Eigen::Matrix3d> about_y, slightly_more;
  for (int i = 1; i <= 10; ++i) {
    about_y.push_back(rotation(Eigen::Vector3d::UnitY(), i));
    slightly_more.push_back(rotation(Eigen::Vector3d::UnitY(), 1.01 * i));
  }
  // Rotations about one axis cannot show a tilt about that axis.
  EXPECT_FALSE(fit_rotation_offset(slightly_more, about_y).ok);
  const std::vector<Eigen::Matrix3d> two(about_y.begin(), about_y.begin() + 2);
  EXPECT_FALSE(fit_rotation_offset(two, two).ok);
  EXPECT_FALSE(fit_rotation_offset(about_y, two).ok);
  std::vector<Eigen::Matrix3d> broken = about_y;
  broken[4](1, 2) = std::nan("");
  EXPECT_FALSE(fit_rotation_offset(broken, about_y).ok);
}

}  // namespace
}  // namespace evaluation
}  // namespace hybrid_vo
