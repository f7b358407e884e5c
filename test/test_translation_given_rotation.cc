// Translation with a known rotation: the two-point solver on random noiseless instances and
// degenerate ones, and the RANSAC estimator on noisy points of a single plane (where the
// five-point model is ambiguous) with outliers, and on bad input.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/estimation/translation_given_rotation.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/solvers/relpose_known_rotation_2pt.h"

namespace hybrid_vo {
namespace {

struct Scene {
  RelativePose truth;
  std::vector<Eigen::Vector3d> X;  // camera 1
};

// Points in front of both cameras; on the plane z = 4 + 0.3 x when `planar`.
Scene random_scene(std::mt19937* rng, int n, bool planar) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Scene s;
  s.truth.R = rotation_about(Eigen::Vector3d(u(*rng), u(*rng), u(*rng)).normalized(), 0.2 * u(*rng));
  s.truth.t = Eigen::Vector3d(u(*rng), u(*rng), u(*rng)).normalized();
  while (static_cast<int>(s.X.size()) < n) {
    const double x = 2.0 * u(*rng), y = 2.0 * u(*rng);
    const double z = planar ? 4.0 + 0.3 * x : 4.0 + 2.0 * u(*rng);
    const Eigen::Vector3d X(x, y, z);
    if ((s.truth.R * X + s.truth.t).z() > 0.5) s.X.push_back(X);
  }
  return s;
}

Eigen::Vector2d project(const Eigen::Vector3d& X) { return X.head<2>() / X.z(); }

TEST(RelposeKnownRotation2pt, RecoversTheTranslationOfNoiselessInstances) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 1000; ++trial) {
    const Scene s = random_scene(&rng, 2, false);
    std::array<Eigen::Vector2d, 2> x1, x2;
    for (int i = 0; i < 2; ++i) {
      x1[i] = project(s.X[i]);
      x2[i] = project(s.truth.R * s.X[i] + s.truth.t);
    }
    RelativePoses poses;
    ASSERT_EQ(relpose_known_rotation_2pt(s.truth.R, x1, x2, &poses), 1);
    EXPECT_LT(translation_error(poses[0].t, s.truth.t), 1e-8);
    EXPECT_NEAR(poses[0].t.norm(), 1.0, 1e-12);
    EXPECT_TRUE(poses[0].R.isApprox(s.truth.R));
  }
}

TEST(RelposeKnownRotation2pt, DegenerateInputGivesNoPose) {
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  RelativePoses poses;
  const Eigen::Vector2d a(0.1, 0.2), b(0.15, 0.2);
  EXPECT_EQ(relpose_known_rotation_2pt(R, {a, a}, {b, b}, &poses), 0);  // one epipolar plane
  EXPECT_EQ(relpose_known_rotation_2pt(R, {a, b}, {a, b}, &poses), 0);  // no parallax at all
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(relpose_known_rotation_2pt(R, {a, Eigen::Vector2d(nan, 0)}, {b, a}, &poses), 0);
  EXPECT_TRUE(poses.empty());
}

TEST(TranslationGivenRotation, FindsTheTranslationOfANoisyPlaneWithOutliers) {
  std::mt19937 rng(2);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::uniform_real_distribution<double> anywhere(0.0, 640.0);
  const PinholeCamera camera(500.0, 500.0, 320.0, 240.0);
  std::vector<double> errors;
  for (int trial = 0; trial < 50; ++trial) {
    const Scene s = random_scene(&rng, 150, true);
    std::vector<PointMatch> points;
    for (const Eigen::Vector3d& X : s.X) {
      PointMatch m;
      m.x1 = camera.denormalize(project(X)) + Eigen::Vector2d(noise(rng), noise(rng));
      m.x2 = camera.denormalize(project(s.truth.R * X + s.truth.t)) +
             Eigen::Vector2d(noise(rng), noise(rng));
      points.push_back(m);
    }
    for (int k = 0; k < 60; ++k)  // 30 % outliers
      points.push_back({Eigen::Vector2d(anywhere(rng), anywhere(rng)),
                        Eigen::Vector2d(anywhere(rng), anywhere(rng))});
    TranslationGivenRotationOptions options;
    options.point_threshold_px = 2.0;
    const TranslationEstimate e =
        estimate_translation_given_rotation(camera, camera, points, s.truth.R, options);
    ASSERT_TRUE(e.ok);
    errors.push_back(translation_error(e.pose.t, s.truth.t) * 180.0 / M_PI);
    EXPECT_GE(e.num_inliers, 130);
    int outliers_in = 0;
    for (size_t i = 150; i < points.size(); ++i) outliers_in += e.inliers[i];
    EXPECT_LT(outliers_in, 10);
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 1.0);
  EXPECT_LT(errors.back(), 5.0);
}

TEST(TranslationGivenRotation, BadInputGivesNoTranslation) {
  const PinholeCamera camera(500.0, 500.0, 320.0, 240.0);
  EXPECT_FALSE(estimate_translation_given_rotation(camera, camera, {}, Eigen::Matrix3d::Identity()).ok);
  std::vector<PointMatch> same(20, PointMatch{Eigen::Vector2d(100, 100), Eigen::Vector2d(100, 100)});
  const TranslationEstimate e =
      estimate_translation_given_rotation(camera, camera, same, Eigen::Matrix3d::Identity());
  EXPECT_FALSE(e.ok);
  EXPECT_TRUE(all_finite(e.pose.t));
  Eigen::Matrix3d nan_R = Eigen::Matrix3d::Identity();
  nan_R(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(estimate_translation_given_rotation(camera, camera, same, nan_R).ok);
  EXPECT_FALSE(
      estimate_translation_given_rotation(PinholeCamera(), camera, same, Eigen::Matrix3d::Identity())
          .ok);
}

}  // namespace
}  // namespace hybrid_vo
