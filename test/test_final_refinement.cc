// The final Ceres refinement (paper Sec. 4) on synthetic two-view scenes: f = 600 px, 800x600
// images, points 4-12 m in front of camera 1, a ~10 degree rotation and a 0.5 m baseline.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/estimation/final_refinement.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;
const PinholeCamera kCamera(600.0, 600.0, 400.0, 300.0, 800, 600);

struct Scene {
  RelativePose truth;        // unit t
  Eigen::Vector3d t_metric;  // R X1 + t_metric, |t_metric| = 0.5 m
  std::vector<PointMatch> points;
  std::vector<VpMatch> vps;
  std::vector<LineMatch> lines;
  std::vector<int> line_vp;
};

Eigen::Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
}

// Projects X1 (camera-1 frame) into both images; false when behind a camera or outside image 2.
bool project(const Scene& s, const Eigen::Vector3d& X1, Eigen::Vector2d* x1, Eigen::Vector2d* x2) {
  const Eigen::Vector3d X2 = s.truth.R * X1 + s.t_metric;
  if (X1.z() < 0.5 || X2.z() < 0.5) return false;
  *x1 = kCamera.denormalize(X1.head<2>() / X1.z());
  *x2 = kCamera.denormalize(X2.head<2>() / X2.z());
  return kCamera.in_image(*x2);
}

Eigen::Vector3d random_point(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::Vector2d pixel(799.0 * u(rng), 599.0 * u(rng));
  return (4.0 + 8.0 * u(rng)) * homogeneous(kCamera.normalize(pixel));
}

// `num_vps` Manhattan directions; lines along them, labelled. Noise in pixels on every point and
// endpoint; VP directions exact (sign of d2 flipped on every other VP, sign unknown).
Scene make_scene(std::mt19937_64& rng, int num_points, int num_vps, int num_lines, double noise) {
  std::normal_distribution<double> n;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Scene s;
  s.truth.R = rotation_about(random_unit(rng), 10.0 * kDeg);
  // Mostly sideways motion with some forward component.
  const Eigen::Vector3d centre2 =
      0.5 * Eigen::Vector3d(1.0, 0.2 * n(rng), 0.3 * n(rng)).normalized();
  s.t_metric = -s.truth.R * centre2;
  s.truth.t = s.t_metric.normalized();
  while (static_cast<int>(s.points.size()) < num_points) {
    PointMatch m;
    if (!project(s, random_point(rng), &m.x1, &m.x2)) continue;
    m.x1 += noise * Eigen::Vector2d(n(rng), n(rng));
    m.x2 += noise * Eigen::Vector2d(n(rng), n(rng));
    s.points.push_back(m);
  }
  const Eigen::Matrix3d frame = rotation_about(random_unit(rng), 0.5 + u(rng));
  for (int k = 0; k < num_vps; ++k) {
    VpMatch vp;
    vp.d1 = frame.col(k);
    vp.d2 = (k % 2 ? -1.0 : 1.0) * (s.truth.R * vp.d1);
    s.vps.push_back(vp);
  }
  while (num_vps > 0 && static_cast<int>(s.lines.size()) < num_lines) {
    const int k = static_cast<int>(s.lines.size()) % num_vps;
    const Eigen::Vector3d X = random_point(rng);
    const double half = 0.25 + 0.75 * u(rng);
    LineMatch line;
    if (!project(s, X - half * s.vps[k].d1, &line.s1.p1, &line.s2.p1) ||
        !project(s, X + half * s.vps[k].d1, &line.s1.p2, &line.s2.p2) || line.s1.length() < 20.0 ||
        line.s2.length() < 20.0)
      continue;
    for (Eigen::Vector2d* p : {&line.s1.p1, &line.s1.p2, &line.s2.p1, &line.s2.p2})
      *p += noise * Eigen::Vector2d(n(rng), n(rng));
    s.lines.push_back(line);
    s.line_vp.push_back(k);
  }
  return s;
}

RelativePose perturb(std::mt19937_64& rng, const RelativePose& pose, double rotation_angle,
                     double translation_angle) {
  const Eigen::Vector3d axis_t = pose.t.cross(random_unit(rng)).normalized();
  return {rotation_about(random_unit(rng), rotation_angle) * pose.R,
          rotation_about(axis_t, translation_angle) * pose.t};
}

// w with R_estimate = exp([w]x) R_truth: the left increment of the covariance.
Eigen::Vector3d rotation_error_vector(const Eigen::Matrix3d& estimate,
                                      const Eigen::Matrix3d& truth) {
  const Eigen::AngleAxisd aa(Eigen::Matrix3d(estimate * truth.transpose()));
  return aa.angle() * aa.axis();
}

bool all_finite(const FinalRefinementResult& r) {
  return hybrid_vo::all_finite(r.pose.R) && hybrid_vo::all_finite(r.pose.t) &&
         hybrid_vo::all_finite(r.covariance) && std::isfinite(r.initial_cost) &&
         std::isfinite(r.final_cost);
}

TEST(FinalRefinement, ConvergesToTheTruthOnNoiselessData) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 30; ++trial) {
    // Points alone, then everything with fixed VPs, then with VP directions refined from lines.
    const bool everything = trial % 3 != 0;
    const bool free_vps = trial % 3 == 2;
    const Scene s = make_scene(rng, 200, everything ? 3 : 0, everything ? 60 : 0, 0.0);
    const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 2.0 * kDeg);
    FinalRefinementOptions options;
    options.refine_vp_directions = free_vps;
    const FinalRefinementResult r = refine_relative_pose_ceres(
        kCamera, kCamera, s.points, s.vps, s.lines, s.line_vp, start, options);
    ASSERT_TRUE(r.success);
    EXPECT_LT(rotation_error(r.pose.R, s.truth.R), 1e-6);
    EXPECT_LT(translation_error(r.pose.t, s.truth.t), 1e-6);
    EXPECT_NEAR(r.pose.t.norm(), 1.0, 1e-12);
    EXPECT_LT(r.final_cost, 1e-10);
    EXPECT_GT(r.initial_cost, 1.0);
    EXPECT_EQ(r.num_point_residuals, 200);
    EXPECT_EQ(r.num_vp_residuals, everything && !free_vps ? 3 : 0);
    EXPECT_EQ(r.num_refined_vps, free_vps ? 3 : 0);
    EXPECT_EQ(r.num_line_residuals, everything ? 120 : 0);
  }
}

// Detected VPs carry the error of their fit; refining each direction from its segments in both
// views beats trusting them (the paper's point that lines carry the rotation).
TEST(FinalRefinement, RefinedVpDirectionsBeatNoisyDetectedOnes) {
  std::mt19937_64 rng(9);
  double fixed_error = 0.0, free_error = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    Scene s = make_scene(rng, 15, 3, 90, 0.5);
    // Detected VPs 0.5 degrees off in each image.
    for (VpMatch& v : s.vps) {
      v.d1 = rotation_about(v.d1.unitOrthogonal(), 0.5 * kDeg) * v.d1;
      v.d2 = rotation_about(v.d2.unitOrthogonal(), 0.5 * kDeg) * v.d2;
    }
    const RelativePose start = perturb(rng, s.truth, 0.5 * kDeg, 1.0 * kDeg);
    FinalRefinementOptions options;
    options.vp_sigma_deg = 0.05;  // trusting the detected VPs
    options.refine_vp_directions = false;
    fixed_error += rotation_error(refine_relative_pose_ceres(kCamera, kCamera, s.points, s.vps,
                                                             s.lines, s.line_vp, start, options)
                                      .pose.R,
                                  s.truth.R);
    options.refine_vp_directions = true;
    free_error += rotation_error(refine_relative_pose_ceres(kCamera, kCamera, s.points, s.vps,
                                                            s.lines, s.line_vp, start, options)
                                     .pose.R,
                                 s.truth.R);
  }
  EXPECT_LT(free_error, 0.5 * fixed_error);
}

TEST(FinalRefinement, CovariancePredictsTheErrorOnNoisyData) {
  std::mt19937_64 rng(2);
  const int trials = 50;
  double rotation_nees = 0.0, translation_nees = 0.0, sigma2 = 0.0;
  double rotation_error_sum = 0.0, translation_error_sum = 0.0;
  for (int trial = 0; trial < trials; ++trial) {
    const Scene s = make_scene(rng, 300, 0, 0, 0.5);
    const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 2.0 * kDeg);
    const FinalRefinementResult r =
        refine_relative_pose_ceres(kCamera, kCamera, s.points, {}, {}, {}, start);
    ASSERT_TRUE(r.success);
    ASSERT_TRUE(r.covariance_valid);
    // Well below the start (1 and 2 degrees off); the mean is checked below.
    EXPECT_LT(rotation_error(r.pose.R, s.truth.R), 0.5 * kDeg);
    EXPECT_LT(translation_error(r.pose.t, s.truth.t), 1.0 * kDeg);
    rotation_error_sum += rotation_error(r.pose.R, s.truth.R);
    translation_error_sum += translation_error(r.pose.t, s.truth.t);
    // Symmetric, positive semi-definite, nothing along t (rank 5).
    EXPECT_LT((r.covariance - r.covariance.transpose()).norm(), 1e-12 * r.covariance.norm());
    using Matrix6d = Eigen::Matrix<double, 6, 6>;
    const double min_eigenvalue =
        Eigen::SelfAdjointEigenSolver<Matrix6d>(r.covariance).eigenvalues().minCoeff();
    EXPECT_GT(min_eigenvalue, -1e-9 * r.covariance.norm());
    const Eigen::Matrix3d translation_covariance = r.covariance.bottomRightCorner<3, 3>();
    EXPECT_LT((translation_covariance * r.pose.t).norm(), 1e-9 * translation_covariance.norm());
    // Normalised squared errors: chi-square with 3 (rotation) and 2 (translation) dof.
    const Eigen::Vector3d w = rotation_error_vector(r.pose.R, s.truth.R);
    rotation_nees += w.dot(r.covariance.topLeftCorner<3, 3>().ldlt().solve(w));
    Eigen::Matrix<double, 3, 2> B;
    B.col(0) = r.pose.t.unitOrthogonal();
    B.col(1) = r.pose.t.cross(B.col(0));
    const Eigen::Vector2d e = B.transpose() * (r.pose.t - s.truth.t);
    const Eigen::Matrix2d S = B.transpose() * r.covariance.bottomRightCorner<3, 3>() * B;
    translation_nees += e.dot(S.ldlt().solve(e));
    sigma2 += r.sigma2;
  }
  rotation_nees /= trials;
  translation_nees /= trials;
  std::cout << "mean error: rotation " << rotation_error_sum / trials / kDeg
            << " deg (start 1), translation " << translation_error_sum / trials / kDeg
            << " deg (start 2)\n";
  EXPECT_LT(rotation_error_sum / trials, 0.1 * kDeg);
  EXPECT_LT(translation_error_sum / trials, 0.25 * 2.0 * kDeg);
  std::cout << "mean NEES: rotation " << rotation_nees << " (3 dof), translation "
            << translation_nees << " (2 dof); mean sigma^2 " << sigma2 / trials
            << " px^2 (noise 0.5 px)\n";
  EXPECT_GT(rotation_nees, 1.0);
  EXPECT_LT(rotation_nees, 6.0);
  EXPECT_GT(translation_nees, 0.5);
  EXPECT_LT(translation_nees, 4.0);
}

TEST(FinalRefinement, CauchyLossResistsGrossOutliers) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  FinalRefinementOptions least_squares;
  least_squares.point_loss_px = 0.0;
  const int trials = 10;
  double clean_error = 0.0, robust_error = 0.0, plain_error = 0.0;
  for (int trial = 0; trial < trials; ++trial) {
    const Scene s = make_scene(rng, 500, 0, 0, 0.5);
    std::vector<PointMatch> contaminated = s.points;
    for (size_t i = 0; i < contaminated.size(); i += 5)  // 20 %: anywhere in image 2
      contaminated[i].x2 = Eigen::Vector2d(799.0 * u(rng), 599.0 * u(rng));
    const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 2.0 * kDeg);
    const FinalRefinementResult clean =
        refine_relative_pose_ceres(kCamera, kCamera, s.points, {}, {}, {}, start);
    const FinalRefinementResult robust =
        refine_relative_pose_ceres(kCamera, kCamera, contaminated, {}, {}, {}, start);
    const FinalRefinementResult plain = refine_relative_pose_ceres(
        kCamera, kCamera, contaminated, {}, {}, {}, start, least_squares);
    ASSERT_TRUE(clean.success);
    ASSERT_TRUE(robust.success);
    ASSERT_TRUE(plain.success);
    EXPECT_LT(rotation_error(robust.pose.R, s.truth.R), 0.25 * kDeg);
    EXPECT_LT(translation_error(robust.pose.t, s.truth.t), 1.5 * kDeg);
    clean_error += pose_error(clean.pose, s.truth);
    robust_error += pose_error(robust.pose, s.truth);
    plain_error += pose_error(plain.pose, s.truth);
  }
  std::cout << "mean pose error: inliers only " << clean_error / trials / kDeg
            << " deg; with 20 % outliers, Cauchy " << robust_error / trials / kDeg
            << " deg, least squares " << plain_error / trials / kDeg << " deg\n";
  EXPECT_LT(robust_error, 2.5 * clean_error);
  EXPECT_LT(robust_error, 0.1 * plain_error);
}

TEST(FinalRefinement, VanishingPointsAlonePinTheRotation) {
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 10; ++trial) {
    const Scene s = make_scene(rng, 0, 2, 0, 0.0);
    std::vector<VpMatch> vps = s.vps;
    vps[0].sign_known = trial % 2 == 0;  // d2 = +R d1 for VP 0
    const RelativePose start = perturb(rng, s.truth, 2.0 * kDeg, 5.0 * kDeg);
    const FinalRefinementResult r =
        refine_relative_pose_ceres(kCamera, kCamera, {}, vps, {}, {}, start);
    ASSERT_TRUE(r.success);
    EXPECT_EQ(r.num_vp_residuals, 2);
    EXPECT_LT(rotation_error(r.pose.R, s.truth.R), 1e-7);
    EXPECT_LT((r.pose.t - start.t).norm(), 1e-15);  // t is not a parameter without points
    EXPECT_FALSE(r.covariance_valid);               // so the 6x6 covariance is undefined
  }
  // One VP leaves the rotation about it free (three rows, two independent): refused.
  const Scene s = make_scene(rng, 0, 3, 0, 0.0);
  const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 0.0);
  const FinalRefinementResult one =
      refine_relative_pose_ceres(kCamera, kCamera, {}, {s.vps[0]}, {}, {}, start);
  EXPECT_FALSE(one.success);
  EXPECT_EQ(one.pose.R, start.R);
}

TEST(FinalRefinement, LabelledLinesPullTheRotation) {
  std::mt19937_64 rng(5);
  FinalRefinementOptions lines_only;
  lines_only.vp_sigma_deg = std::numeric_limits<double>::infinity();  // no VP residuals:
  // the rotation comes from the lines alone
  for (int trial = 0; trial < 10; ++trial) {
    const Scene s = make_scene(rng, 0, 3, 60, 0.0);
    const RelativePose start = perturb(rng, s.truth, 2.0 * kDeg, 0.0);
    const FinalRefinementResult r = refine_relative_pose_ceres(kCamera, kCamera, {}, s.vps, s.lines,
                                                               s.line_vp, start, lines_only);
    ASSERT_TRUE(r.success);
    EXPECT_EQ(r.num_vp_residuals, 0);
    EXPECT_EQ(r.num_line_residuals, 120);
    EXPECT_LT(rotation_error(r.pose.R, s.truth.R), 1e-7);
  }
  // With few noisy points, noiseless labelled lines improve the rotation.
  FinalRefinementOptions without_lines = lines_only;
  without_lines.line_vp_sigma_px = std::numeric_limits<double>::infinity();
  double with_error = 0.0, without_error = 0.0;
  std::normal_distribution<double> n;
  for (int trial = 0; trial < 20; ++trial) {
    Scene s = make_scene(rng, 15, 3, 60, 0.0);
    for (PointMatch& m : s.points) {
      m.x1 += 2.0 * Eigen::Vector2d(n(rng), n(rng));
      m.x2 += 2.0 * Eigen::Vector2d(n(rng), n(rng));
    }
    const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 2.0 * kDeg);
    const FinalRefinementResult with = refine_relative_pose_ceres(
        kCamera, kCamera, s.points, s.vps, s.lines, s.line_vp, start, lines_only);
    const FinalRefinementResult without = refine_relative_pose_ceres(
        kCamera, kCamera, s.points, s.vps, s.lines, s.line_vp, start, without_lines);
    ASSERT_TRUE(with.success);
    ASSERT_TRUE(without.success);
    EXPECT_EQ(without.num_line_residuals, 0);
    with_error += rotation_error(with.pose.R, s.truth.R);
    without_error += rotation_error(without.pose.R, s.truth.R);
  }
  std::cout << "mean rotation error, 15 points at 2 px: with lines " << with_error / 20 / kDeg
            << " deg, without " << without_error / 20 / kDeg << " deg\n";
  EXPECT_LT(with_error, 0.2 * without_error);
}

TEST(FinalRefinement, BadInputFailsOrIsSkippedNeverNaN) {
  std::mt19937_64 rng(6);
  const Scene s = make_scene(rng, 50, 3, 30, 0.5);
  const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 2.0 * kDeg);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  // Empty, and too few rows: the pose is returned unchanged.
  FinalRefinementResult r = refine_relative_pose_ceres(kCamera, kCamera, {}, {}, {}, {}, start);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.pose.R, start.R);
  EXPECT_TRUE(r.pose.t.isApprox(start.t));
  const std::vector<PointMatch> four(s.points.begin(), s.points.begin() + 4);
  r = refine_relative_pose_ceres(kCamera, kCamera, four, {}, {}, {}, start);
  EXPECT_FALSE(r.success);
  EXPECT_TRUE(all_finite(r));

  // Invalid cameras.
  for (PinholeCamera bad :
       {PinholeCamera(0.0, 600.0, 400.0, 300.0), PinholeCamera(600.0, nan, 400.0, 300.0),
        PinholeCamera(600.0, 600.0, inf, 300.0), PinholeCamera(-600.0, 600.0, 400.0, 300.0)}) {
    r = refine_relative_pose_ceres(bad, kCamera, s.points, s.vps, s.lines, s.line_vp, start);
    EXPECT_FALSE(r.success);
    EXPECT_TRUE(all_finite(r));
    r = refine_relative_pose_ceres(kCamera, bad, s.points, s.vps, s.lines, s.line_vp, start);
    EXPECT_FALSE(r.success);
  }

  // Non-finite, zero or improper initial poses.
  for (int which = 0; which < 4; ++which) {
    RelativePose bad = start;
    if (which == 0) bad.R(1, 2) = nan;
    if (which == 1) bad.t.x() = inf;
    if (which == 2) bad.t.setZero();
    if (which == 3) bad.R = -bad.R;  // determinant -1
    r = refine_relative_pose_ceres(kCamera, kCamera, s.points, s.vps, s.lines, s.line_vp, bad);
    EXPECT_FALSE(r.success) << which;
  }

  // Non-finite options.
  FinalRefinementOptions bad_options;
  bad_options.vp_sigma_deg = nan;
  r = refine_relative_pose_ceres(kCamera, kCamera, s.points, s.vps, s.lines, s.line_vp, start,
                                 bad_options);
  EXPECT_FALSE(r.success);

  // Bad items are skipped, the rest refined.
  std::vector<PointMatch> points = s.points;
  points[3].x1.x() = nan;
  points[7].x2.y() = inf;
  std::vector<VpMatch> vps = s.vps;
  vps.push_back(VpMatch());
  vps.back().d1 = Eigen::Vector3d::Zero();  // index 3: unusable
  vps.push_back(VpMatch());
  vps.back().d2.z() = nan;  // index 4: unusable
  std::vector<LineMatch> lines = s.lines;
  std::vector<int> labels = s.line_vp;
  labels[0] = -1;                   // unlabelled
  labels[1] = 3;                    // names an unusable VP
  labels[2] = 4;                    // names an unusable VP
  labels[3] = 99;                   // out of range
  labels[4] = -7;                   // out of range
  lines[5].s1.p2 = lines[5].s1.p1;  // zero length: the image-2 half still counts
  lines[6].s2.p1.x() = nan;         // likewise the image-1 half
  labels.pop_back();                // the last line is left unlabelled
  FinalRefinementOptions fixed_vps;
  fixed_vps.refine_vp_directions = false;  // so that every VP keeps its residual to count
  r = refine_relative_pose_ceres(kCamera, kCamera, points, vps, lines, labels, start, fixed_vps);
  ASSERT_TRUE(r.success);
  EXPECT_TRUE(all_finite(r));
  EXPECT_EQ(r.num_point_residuals, 48);
  EXPECT_EQ(r.num_vp_residuals, 3);
  EXPECT_EQ(r.num_line_residuals, 2 * (30 - 5 - 1) - 2);
  EXPECT_LT(pose_error(r.pose, s.truth), 0.25 * pose_error(start, s.truth));

  // Every point NaN and no other data.
  std::vector<PointMatch> all_nan(10);
  for (PointMatch& m : all_nan) m.x2.x() = nan;
  r = refine_relative_pose_ceres(kCamera, kCamera, all_nan, {}, {}, {}, start);
  EXPECT_FALSE(r.success);
  EXPECT_TRUE(all_finite(r));

  // Pure rotation data: points at infinity leave t free; no NaN, covariance flagged or finite.
  Scene rotation_only = s;
  for (PointMatch& m : rotation_only.points) {
    const Eigen::Vector3d ray = homogeneous(kCamera.normalize(m.x1));
    const Eigen::Vector3d x2 = s.truth.R * ray;
    m.x2 = kCamera.denormalize(x2.head<2>() / x2.z());
  }
  r = refine_relative_pose_ceres(kCamera, kCamera, rotation_only.points, {}, {}, {}, start);
  EXPECT_TRUE(all_finite(r));
  EXPECT_FALSE(r.covariance_valid);
}

TEST(FinalRefinement, Timing) {
  std::mt19937_64 rng(7);
  const Scene s = make_scene(rng, 1500, 3, 100, 0.5);
  const int runs = 20;
  for (bool covariance : {false, true}) {
    FinalRefinementOptions options;
    options.compute_covariance = covariance;
    std::vector<double> ms;
    int iterations = 0;
    for (int run = 0; run < runs; ++run) {
      const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 1.0 * kDeg);
      const auto begin = std::chrono::steady_clock::now();
      const FinalRefinementResult r = refine_relative_pose_ceres(
          kCamera, kCamera, s.points, s.vps, s.lines, s.line_vp, start, options);
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin)
              .count());
      ASSERT_TRUE(r.success);
      EXPECT_EQ(r.covariance_valid, covariance);
      EXPECT_LT(rotation_error(r.pose.R, s.truth.R), 0.1 * kDeg);
      EXPECT_LT(translation_error(r.pose.t, s.truth.t), 0.5 * kDeg);
      iterations += r.iterations;
    }
    std::sort(ms.begin(), ms.end());
    std::cout << "refinement of 1500 points + 3 VPs + 100 labelled lines, 1 deg off, "
              << (covariance ? "with" : "without") << " covariance: median " << ms[runs / 2]
              << " ms, min " << ms.front() << " ms, " << double(iterations) / runs
              << " iterations\n";
  }
}

}  // namespace
}  // namespace hybrid_vo

namespace hybrid_vo {
namespace {

// 30 point matches with 2 px noise, and 3 exact VPs with 60 exact labelled segments: the lines
// alone pin the rotation far better than the points.
Scene noisy_points_exact_lines(std::mt19937_64& rng, std::normal_distribution<double>& n) {
  Scene s = make_scene(rng, 30, 3, 60, 0.0);
  for (PointMatch& m : s.points) {
    m.x1 += 2.0 * Eigen::Vector2d(n(rng), n(rng));
    m.x2 += 2.0 * Eigen::Vector2d(n(rng), n(rng));
  }
  return s;
}

RefinementData refinement_data(const Scene& s) {
  RefinementData data;
  data.points = s.points;
  data.vps = s.vps;
  data.lines = s.lines;
  data.line_vp = s.line_vp;
  return data;
}

// A VP prior (e.g. a tracked direction) pins the rotation through image 2's segments: with few
// noisy points, an exact prior in camera 1 and exact segments in image 2, the rotation about every
// axis the VPs span is the prior's, also when camera 1's segments are left out (includes_view1).
TEST(FinalRefinement, VpPriorPullsTheRotation) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n;
  double with_error = 0.0, without_error = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const Scene s = noisy_points_exact_lines(rng, n);
    RefinementData data = refinement_data(s);
    const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 2.0 * kDeg);
    FinalRefinementOptions options;
    options.point_sigma_px = 2.0;
    options.line_vp_sigma_px = 0.1;
    const FinalRefinementResult without =
        refine_relative_pose_ceres(kCamera, kCamera, s.points, {}, {}, {}, start, options);
    for (const VpMatch& v : s.vps) {
      VpPrior prior;
      prior.valid = true;
      prior.direction = v.d1;
      const double sigma = 0.01 * kDeg;
      prior.covariance = sigma * sigma * (Eigen::Matrix3d::Identity() - v.d1 * v.d1.transpose());
      prior.includes_view1 = true;
      data.vp_priors.push_back(prior);
    }
    const FinalRefinementResult with =
        refine_relative_pose_ceres(kCamera, kCamera, data, start, options);
    ASSERT_TRUE(with.success);
    EXPECT_EQ(with.num_vp_priors, 3);
    EXPECT_EQ(with.num_line_residuals, 60);  // image 2 only
    with_error += rotation_error(with.pose.R, s.truth.R);
    without_error += rotation_error(without.pose.R, s.truth.R);
  }
  std::cout << "mean rotation error, 30 points at 2 px: with exact VP priors "
            << with_error / 20 / kDeg << " deg, points alone " << without_error / 20 / kDeg
            << " deg\n";
  EXPECT_LT(with_error, 0.1 * without_error);
}

}  // namespace
}  // namespace hybrid_vo

namespace hybrid_vo {
namespace {

// vp_sigma_scale weakens one VP's segments without touching the rest: scale 1 is the default, a
// huge scale leaves the points' rotation, and a scale that is not finite and positive fails.
TEST(FinalRefinement, VpSigmaScaleWeakensItsVpOnly) {
  std::mt19937_64 rng(12);
  std::normal_distribution<double> n;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  FinalRefinementOptions options;
  options.point_sigma_px = 2.0;
  options.line_vp_sigma_px = 0.1;
  FinalRefinementOptions points_only = options;
  points_only.line_vp_sigma_px = inf;
  points_only.vp_sigma_deg = inf;
  for (int trial = 0; trial < 10; ++trial) {
    const Scene s = noisy_points_exact_lines(rng, n);
    RefinementData data = refinement_data(s);
    const RelativePose start = perturb(rng, s.truth, 1.0 * kDeg, 2.0 * kDeg);
    auto refine = [&](const FinalRefinementOptions& o) {
      return refine_relative_pose_ceres(kCamera, kCamera, data, start, o);
    };
    const FinalRefinementResult plain = refine(options), points = refine(points_only);
    data.vp_sigma_scale.assign(3, 1.0);
    const FinalRefinementResult ones = refine(options);
    data.vp_sigma_scale.assign(3, 1e6);
    const FinalRefinementResult weak = refine(options);
    ASSERT_TRUE(plain.success && points.success && ones.success && weak.success);
    EXPECT_LT(rotation_error(ones.pose.R, plain.pose.R), 1e-12);
    EXPECT_LT(rotation_error(weak.pose.R, points.pose.R), 1e-3 * kDeg);
    // The exact lines pull the rotation well away from the noisy points' one.
    EXPECT_GT(rotation_error(plain.pose.R, points.pose.R), 0.02 * kDeg);
    EXPECT_LT(rotation_error(plain.pose.R, s.truth.R), rotation_error(points.pose.R, s.truth.R));
    // Only VP 0 weakened: its segments no longer count, the other two still pin the rotation.
    data.vp_sigma_scale = {1e6, 1.0, 1.0};
    const FinalRefinementResult one_weak = refine(options);
    ASSERT_TRUE(one_weak.success);
    EXPECT_LT(rotation_error(one_weak.pose.R, s.truth.R),
              0.2 * rotation_error(points.pose.R, s.truth.R));
    for (double bad : {nan, inf, 0.0, -1.0}) {
      data.vp_sigma_scale = {1.0, bad, 1.0};
      EXPECT_FALSE(refine(options).success) << bad;
    }
  }
}

}  // namespace
}  // namespace hybrid_vo
