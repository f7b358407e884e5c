#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "hybrid_vo/estimation/refine_relative_pose.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

struct Scene {
  RelativePose truth;
  std::vector<Eigen::Vector2d> x1, x2;
  std::vector<Eigen::Vector3d> v1, v2;
};

Scene make_scene(std::mt19937_64& rng, int points, double noise) {
  std::normal_distribution<double> n;
  Scene s;
  s.truth = RelativePose(rotation_about(Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized(), 0.2),
                         Eigen::Vector3d(1.0, 0.2 * n(rng), 0.1 * n(rng)).normalized());
  for (int i = 0; i < points; ++i) {
    const Eigen::Vector3d X(2 * n(rng), 2 * n(rng), 6.0 + n(rng));
    const Eigen::Vector3d X2 = s.truth.apply(X);
    s.x1.push_back(X.head<2>() / X.z() + noise * Eigen::Vector2d(n(rng), n(rng)));
    s.x2.push_back(X2.head<2>() / X2.z() + noise * Eigen::Vector2d(n(rng), n(rng)));
  }
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector3d d = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    s.v1.push_back(d);
    s.v2.push_back(-(s.truth.R * d));  // sign unknown to the refinement
  }
  return s;
}

RelativePose perturb(const RelativePose& pose, double angle) {
  return {rotation_about(Eigen::Vector3d(0.3, -1.0, 0.5).normalized(), angle) * pose.R,
          (pose.t + Eigen::Vector3d(0.0, angle, -angle)).normalized()};
}

TEST(RefineRelativePose, ConvergesToTheTruthOnExactData) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const Scene s = make_scene(rng, 30, 0.0);
    RelativePose pose = perturb(s.truth, 0.05);
    const auto summary = refine_relative_pose(s.x1, s.x2, {}, {}, {}, &pose);
    EXPECT_LT(pose_error(pose, s.truth), 1e-8);
    EXPECT_LT(summary.final_cost, 1e-18);
    EXPECT_GT(summary.initial_cost, summary.final_cost);
  }
}

TEST(RefineRelativePose, VanishingPointsAloneFixTheRotation) {
  std::mt19937_64 rng(2);
  const Scene s = make_scene(rng, 0, 0.0);
  RelativePose pose = perturb(s.truth, 0.05);
  refine_relative_pose({}, {}, s.v1, s.v2, {}, &pose);
  EXPECT_LT(rotation_error(pose.R, s.truth.R), 1e-8);
}

TEST(RefineRelativePose, ReducesTheErrorOnNoisyData) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Scene s = make_scene(rng, 100, 1e-3);
    RelativePose pose = perturb(s.truth, 0.03);
    const double before = pose_error(pose, s.truth);
    refine_relative_pose(s.x1, s.x2, s.v1, s.v2, {}, &pose);
    EXPECT_LT(pose_error(pose, s.truth), 0.25 * before);
    EXPECT_LT(pose_error(pose, s.truth), 1.0 * M_PI / 180.0);
  }
}

TEST(RefineRelativePose, CauchyLossResistsOutliers) {
  std::mt19937_64 rng(4);
  Scene s = make_scene(rng, 100, 1e-3);
  for (int i = 0; i < 20; ++i) s.x2[i] += Eigen::Vector2d(0.05, -0.04);  // gross mismatches
  RelativePoseRefinementOptions robust;
  robust.loss_scale = 2e-3;
  RelativePose plain = perturb(s.truth, 0.02), cauchy = plain;
  refine_relative_pose(s.x1, s.x2, {}, {}, {}, &plain);
  refine_relative_pose(s.x1, s.x2, {}, {}, robust, &cauchy);
  EXPECT_LT(pose_error(cauchy, s.truth), pose_error(plain, s.truth));
  EXPECT_LT(pose_error(cauchy, s.truth), 1.0 * M_PI / 180.0);
}

TEST(RefineRelativePose, BadInputLeavesThePoseUnchanged) {
  std::mt19937_64 rng(5);
  Scene s = make_scene(rng, 20, 0.0);
  const RelativePose start = perturb(s.truth, 0.05);
  RelativePose pose = start;
  // Too few residuals.
  refine_relative_pose({s.x1[0]}, {s.x2[0]}, {}, {}, {}, &pose);
  EXPECT_EQ(pose_error(pose, start), 0.0);
  // Mismatched sizes.
  refine_relative_pose(s.x1, {s.x2[0]}, {}, {}, {}, &pose);
  EXPECT_EQ(pose_error(pose, start), 0.0);
  // NaN in a point.
  s.x1[3].x() = NAN;
  refine_relative_pose(s.x1, s.x2, {}, {}, {}, &pose);
  EXPECT_EQ(pose_error(pose, start), 0.0);
  // Zero translation cannot be refined on the sphere.
  RelativePose zero_t(start.R, Eigen::Vector3d::Zero());
  s.x1[3] = s.x1[4];
  refine_relative_pose(s.x1, s.x2, {}, {}, {}, &zero_t);
  EXPECT_EQ(zero_t.t.norm(), 0.0);
}

TEST(SampsonError, ZeroOnTheEpipolarConstraintAndFirstOrderDistanceOtherwise) {
  const RelativePose pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX());
  const Eigen::Matrix3d E = pose.essential();
  // Pure x-translation: epipolar lines are horizontal, so the Sampson error is half the vertical
  // disparity split over both images.
  EXPECT_NEAR(sampson_error(E, {0.1, 0.2}, {0.3, 0.2}), 0.0, 1e-15);
  EXPECT_NEAR(sampson_error(E, {0.1, 0.2}, {0.3, 0.22}), 0.02 / std::sqrt(2.0), 1e-12);
}

}  // namespace
}  // namespace hybrid_vo
