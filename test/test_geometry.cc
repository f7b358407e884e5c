#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/essential.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/homography.h"
#include "hybrid_vo/geometry/pose.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/geometry/vanishing_point.h"
#include "hybrid_vo/geometry/vp_covariance.h"

namespace hybrid_vo {
namespace {

Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

Eigen::Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
}

TEST(Rotation, BetweenUnitVectorsIncludingAntipodes) {
  std::mt19937_64 rng(2);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Vector3d a = random_unit(rng);
    const Eigen::Vector3d b = (i % 10 == 0) ? Eigen::Vector3d(-a) : random_unit(rng);
    const Eigen::Matrix3d R = rotation_between(a, b);
    EXPECT_LT((R * a - b).norm(), 1e-12);
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
  }
}

TEST(Rotation, FromTwoDirectionsIsExactOnConsistentData) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Matrix3d R = random_rotation(rng);
    const Eigen::Vector3d a1 = random_unit(rng), a2 = random_unit(rng);
    Eigen::Matrix3d estimate;
    ASSERT_TRUE(rotation_from_two_directions(a1, a2, R * a1, R * a2, &estimate));
    EXPECT_LT(rotation_error(estimate, R), 1e-10);
  }
  Eigen::Matrix3d unused;
  const Eigen::Vector3d a = random_unit(rng);
  EXPECT_FALSE(rotation_from_two_directions(a, a, a, a, &unused));
}

TEST(PoseError, AccurateForTinyAngles) {
  const Eigen::Matrix3d R = rotation_about(Eigen::Vector3d::UnitZ(), 1e-12);
  EXPECT_NEAR(rotation_error(Eigen::Matrix3d::Identity(), R), 1e-12, 1e-15);
  EXPECT_NEAR(rotation_error(Eigen::Matrix3d::Identity(),
                             rotation_about(Eigen::Vector3d::UnitX(), 3.0)),
              3.0, 1e-12);
  EXPECT_NEAR(translation_error(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 1e-11, 0)), 1e-11,
              1e-16);
  EXPECT_NEAR(translation_error(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-1, 0, 0)), M_PI, 1e-15);
  EXPECT_NEAR(translation_error(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0)), M_PI / 2, 0);
  const RelativePose a(Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX());
  const RelativePose b(rotation_about(Eigen::Vector3d::UnitY(), 0.1), Eigen::Vector3d(1, 0.2, 0));
  EXPECT_NEAR(pose_error(a, b), std::max(0.1, std::atan(0.2)), 1e-12);
}

TEST(PoseError, AucMatchesTheSuperGlueDefinition) {
  // All errors zero: full area. All failures: none.
  EXPECT_DOUBLE_EQ(pose_auc({0.0, 0.0}, 10.0), 1.0);
  EXPECT_DOUBLE_EQ(pose_auc({180.0, INFINITY, NAN}, 10.0), 0.0);
  // One pair at 5 of 10, one failed: the trapezoid (0,0)-(5,0.5) then 0.5 up to 10.
  EXPECT_NEAR(pose_auc({5.0, 180.0}, 10.0), 0.375, 1e-12);
  // Uniform errors over [0, 10] approach a triangle: area 0.5.
  std::vector<double> uniform;
  for (int i = 0; i < 10000; ++i) uniform.push_back(10.0 * (i + 0.5) / 10000);
  EXPECT_NEAR(pose_auc(uniform, 10.0), 0.5, 1e-3);
  EXPECT_EQ(pose_auc({}, 10.0), 0.0);
}

TEST(Pose, RelativeFromWorldToCameraAndEssential) {
  std::mt19937_64 rng(4);
  const Eigen::Matrix3d R1 = random_rotation(rng), R2 = random_rotation(rng);
  const Eigen::Vector3d t1 = random_unit(rng), t2 = random_unit(rng), X = random_unit(rng) * 3;
  const RelativePose rel = relative_from_world_to_camera(R1, t1, R2, t2);
  EXPECT_LT((rel.apply(R1 * X + t1) - (R2 * X + t2)).norm(), 1e-12);
  const Eigen::Vector3d x1 = R1 * X + t1, x2 = R2 * X + t2;
  EXPECT_NEAR(x2.dot(rel.essential() * x1), 0.0, 1e-12);
  EXPECT_LT((rel.inverse().apply(rel.apply(X)) - X).norm(), 1e-12);
  EXPECT_LT((rel.centre2() - (-rel.R.transpose() * rel.t)).norm(), 1e-15);
}

TEST(Essential, DecompositionContainsTheTruth) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 1000; ++i) {
    const RelativePose truth(random_rotation(rng), random_unit(rng));
    Eigen::Matrix3d Ra, Rb;
    Eigen::Vector3d t;
    ASSERT_TRUE(rotations_from_essential(-2.5 * truth.essential(), &Ra, &Rb, &t));
    EXPECT_LT(std::min(rotation_error(Ra, truth.R), rotation_error(Rb, truth.R)), 1e-12);
    EXPECT_LT(std::min(translation_error(t, truth.t), translation_error(-t, truth.t)), 1e-12);
  }
  Eigen::Matrix3d Ra, Rb;
  Eigen::Vector3d t;
  EXPECT_FALSE(rotations_from_essential(Eigen::Matrix3d::Zero(), &Ra, &Rb, &t));
  Eigen::Matrix3d nan = Eigen::Matrix3d::Identity();
  nan(1, 1) = NAN;
  EXPECT_FALSE(rotations_from_essential(nan, &Ra, &Rb, &t));
}

TEST(Essential, CheiralityPicksTheTruth) {
  std::mt19937_64 rng(6);
  std::normal_distribution<double> n;
  for (int i = 0; i < 200; ++i) {
    const RelativePose truth(rotation_about(random_unit(rng), 0.3 * n(rng)),
                             random_unit(rng));
    Eigen::Vector2d x1[5], x2[5];
    for (int k = 0; k < 5; ++k) {
      const Eigen::Vector3d X(n(rng), n(rng), 6.0 + n(rng));
      const Eigen::Vector3d X2 = truth.apply(X);
      x1[k] = X.head<2>() / X.z();
      x2[k] = X2.head<2>() / X2.z();
    }
    MatchView view;
    view.x1 = x1;
    view.x2 = x2;
    view.num_points = 5;
    RelativePoses poses;
    ASSERT_EQ(poses_from_essential(truth.essential(), view, &poses), 1);
    EXPECT_LT(pose_error(poses[0], truth), 1e-10);
  }
}

TEST(Cheirality, SegmentsDecideTheSignOfT) {
  const RelativePose truth(rotation_about(Eigen::Vector3d::UnitY(), 0.2),
                           Eigen::Vector3d(1, 0.1, 0.05).normalized());
  const Eigen::Vector3d A(-1, 0.5, 5), B(1, -0.3, 6);
  auto project = [](const Eigen::Vector3d& X) { return Eigen::Vector2d(X.head<2>() / X.z()); };
  const LineSegment s1(project(A), project(B)), s2(project(truth.apply(A)), project(truth.apply(B)));
  MatchView view;
  view.s1 = &s1;
  view.s2 = &s2;
  view.num_segments = 1;
  Eigen::Vector3d t = -truth.t;
  ASSERT_TRUE(orient_translation(truth.R, &t, view));
  EXPECT_LT((t - truth.t).norm(), 1e-15);
  t = truth.t;
  ASSERT_TRUE(orient_translation(truth.R, &t, view));
  EXPECT_LT((t - truth.t).norm(), 1e-15);
}

TEST(Cheirality, ConflictingPointsRejectBothSigns) {
  // One point in front, one behind the cameras: no sign of t can fix both.
  const RelativePose truth(Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX());
  const Eigen::Vector3d X[2] = {{0.2, 0.1, 4.0}, {0.3, -0.2, -4.0}};
  Eigen::Vector2d x1[2], x2[2];
  for (int k = 0; k < 2; ++k) {
    x1[k] = X[k].head<2>() / X[k].z();
    const Eigen::Vector3d X2 = truth.apply(X[k]);
    x2[k] = X2.head<2>() / X2.z();
  }
  MatchView view;
  view.x1 = x1;
  view.x2 = x2;
  view.num_points = 2;
  Eigen::Vector3d t = truth.t;
  EXPECT_FALSE(orient_translation(truth.R, &t, view));
}

// The ray form decides like the point form in any rotated copy of camera 2's frame, with the rays
// at arbitrary positive scales; a point behind the cameras makes both reject every sign.
TEST(Cheirality, RaysInARotatedFrameAgreeWithPoints) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n;
  std::uniform_real_distribution<double> scale(0.1, 10.0);
  for (int trial = 0; trial < 200; ++trial) {
    const RelativePose truth(random_rotation(rng),
                             Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized());
    const Eigen::Matrix3d Q = random_rotation(rng);
    Eigen::Vector2d x1[3], x2[3];
    Eigen::Vector3d r[3], q[3];
    const bool one_behind = trial % 4 == 0;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d X(n(rng), n(rng), 6.0 + n(rng));
      if (one_behind && k == 2) X = -X;
      const Eigen::Vector3d X2 = truth.apply(X);
      x1[k] = X.head<2>() / X.z();
      x2[k] = X2.head<2>() / X2.z();
      r[k] = scale(rng) * (Q * truth.R * homogeneous(x1[k]));
      q[k] = scale(rng) * (Q * homogeneous(x2[k]));
    }
    MatchView view;
    view.x1 = x1;
    view.x2 = x2;
    view.num_points = 3;
    for (const double sign : {1.0, -1.0}) {
      Eigen::Vector3d t_points = sign * truth.t, t_rays = sign * (Q * truth.t);
      const bool ok_points = orient_translation(truth.R, &t_points, view);
      const bool ok_rays = orient_translation_rays(r, q, 3, &t_rays);
      ASSERT_EQ(ok_points, ok_rays) << "trial " << trial;
      if (!ok_points) continue;
      EXPECT_LT((Q * t_points - t_rays).norm(), 1e-12);
      if (!one_behind) EXPECT_LT((t_points - truth.t).norm(), 1e-12);
    }
  }
}

TEST(Homography, DecompositionContainsTheTruth) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n;
  for (int i = 0; i < 1000; ++i) {
    const Eigen::Matrix3d R = random_rotation(rng);
    const Eigen::Vector3d t = random_unit(rng) * (0.5 + std::abs(n(rng)));
    Eigen::Vector3d normal = random_unit(rng);
    const double d = 2.0 + std::abs(n(rng));
    const Eigen::Matrix3d H = R + t * normal.transpose() / d;
    // Cameras on opposite sides of the plane (det < 0) decompose just as well.
    PlanarMotion motions[4];
    ASSERT_EQ(decompose_homography(0.3 * H, motions), 4);
    double best = INFINITY;
    for (const PlanarMotion& m : motions) {
      best = std::min(best, rotation_error(m.R, R) + (m.t - t / d).norm() + (m.n - normal).norm());
      EXPECT_LT((m.R + m.t * m.n.transpose() - H).norm(), 1e-9 * H.norm());
    }
    EXPECT_LT(best, 1e-9);
  }
}

TEST(Homography, PureRotationGivesZeroTranslation) {
  std::mt19937_64 rng(8);
  const Eigen::Matrix3d R = random_rotation(rng);
  PlanarMotion motions[4];
  ASSERT_EQ(decompose_homography(7.0 * R, motions), 1);
  EXPECT_LT(rotation_error(motions[0].R, R), 1e-12);
  EXPECT_EQ(motions[0].t.norm(), 0.0);
}

TEST(Homography, SingularOrNonFiniteIsRejected) {
  PlanarMotion motions[4];
  EXPECT_EQ(decompose_homography(Eigen::Matrix3d::Zero(), motions), 0);
  Eigen::Matrix3d rank2 = Eigen::Matrix3d::Identity();
  rank2(2, 2) = 0.0;
  EXPECT_EQ(decompose_homography(rank2, motions), 0);
  Eigen::Matrix3d inf = Eigen::Matrix3d::Identity();
  inf(0, 1) = INFINITY;
  EXPECT_EQ(decompose_homography(inf, motions), 0);
}

TEST(Homography, OrientationFromPointsOrDeterminant) {
  const Eigen::Matrix3d H = rotation_about(Eigen::Vector3d::UnitY(), 0.1) +
                            Eigen::Vector3d(0.2, 0, 0) * Eigen::Vector3d(0, 0, 1).transpose();
  const Eigen::Vector2d x1[2] = {{0.1, 0.2}, {-0.3, 0.1}};
  Eigen::Vector2d x2[2];
  for (int i = 0; i < 2; ++i) x2[i] = (H * homogeneous(x1[i])).hnormalized();
  Eigen::Matrix3d G = -2.0 * H;
  ASSERT_TRUE(orient_homography(&G, x1, x2, 2));
  EXPECT_LT((G - 2.0 * H).norm(), 1e-15);
  G = -H;
  ASSERT_TRUE(orient_homography(&G, nullptr, nullptr, 0));
  EXPECT_GT(G.determinant(), 0.0);
  // The second match puts its point behind camera 2 (x2^T H x1 < 0) while the first is in front.
  Eigen::Vector2d bad2[2] = {x2[0], x2[1]};
  const Eigen::Vector3d h = H * homogeneous(x1[1]);
  bad2[1] = -(h.z() + 1.0) * h.head<2>() / h.head<2>().squaredNorm();
  G = H;
  EXPECT_FALSE(orient_homography(&G, x1, bad2, 2));
}

TEST(Homogeneous, LinesAndIntersections) {
  const Eigen::Vector3d l = line_through({0, 1}, {2, 1});
  EXPECT_NEAR(std::abs(l.dot(Eigen::Vector3d(5, 1, 1))), 0.0, 1e-15);
  EXPECT_NEAR(std::abs(l.dot(Eigen::Vector3d(5, 3, 1))), 2.0, 1e-15);  // signed distance
  EXPECT_EQ(line_through({1, 1}, {1, 1}).norm(), 0.0);
  Eigen::Vector2d x;
  ASSERT_TRUE(intersect_lines(LineSegment({0, 0}, {1, 1}).line(), LineSegment({0, 2}, {2, 0}).line(),
                              &x));
  EXPECT_LT((x - Eigen::Vector2d(1, 1)).norm(), 1e-15);
  EXPECT_FALSE(intersect_lines(LineSegment({0, 0}, {1, 0}).line(),
                               LineSegment({0, 1}, {1, 1}).line(), &x));
  EXPECT_FALSE(intersect_lines(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), &x));
  EXPECT_DOUBLE_EQ(LineSegment({0, 0}, {3, 4}).length(), 5.0);
}

TEST(VanishingPoint, LeastSquaresIntersection) {
  const Eigen::Vector3d v = Eigen::Vector3d(0.3, -0.2, 1.0).normalized();
  std::vector<Eigen::Vector3d> lines;
  for (double angle : {0.1, 0.9, 2.0, 2.8})
    lines.push_back(v.cross(Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.3)));
  const Eigen::Vector3d estimate = vanishing_point_from_lines(lines);
  EXPECT_LT(std::min((estimate - v).norm(), (estimate + v).norm()), 1e-12);
  lines.resize(2);
  const Eigen::Vector3d two = vanishing_point_from_lines(lines);
  EXPECT_LT(std::min((two - v).norm(), (two + v).norm()), 1e-12);
  EXPECT_EQ(vanishing_point_from_lines({lines[0]}).norm(), 0.0);
}

}  // namespace
// Segments through the image of a VP direction: its covariance lies in the tangent plane, grows
// with the segment noise squared, shrinks with more segments, and needs two; as a measurement
// it adds the VP scale's floor to the fit, and is the floor alone without a usable fit.
TEST(VpCovariance, FitAndMeasurement) {
  Eigen::Matrix3d K;
  K << 500, 0, 320, 0, 500, 240, 0, 0, 1;
  const Eigen::Vector3d d = Eigen::Vector3d(0.3, -0.1, 1.0).normalized();
  const Eigen::Vector2d v = (K * d).hnormalized();
  std::vector<LineSegment> segments;
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(50, 400), Eigen::Vector2d(600, 420),
                                   Eigen::Vector2d(100, 60), Eigen::Vector2d(620, 30)})
    segments.emplace_back(p, p + 0.5 * (v - p));
  Eigen::Matrix3d C, C2, few;
  ASSERT_TRUE(vp_direction_covariance(K, segments, d, 0.5, &C));
  EXPECT_LT((C * d).norm(), 1e-12 * C.norm());
  EXPECT_LT((C - C.transpose()).norm(), 1e-12 * C.norm());
  EXPECT_GT(C.trace(), 0.0);
  ASSERT_TRUE(vp_direction_covariance(K, segments, d, 1.0, &C2));
  EXPECT_NEAR(C2.trace(), 4.0 * C.trace(), 1e-9 * C2.trace());
  const std::vector<LineSegment> two(segments.begin(), segments.begin() + 2);
  ASSERT_TRUE(vp_direction_covariance(K, two, d, 0.5, &few));
  EXPECT_GT(few.trace(), C.trace());
  const std::vector<LineSegment> one(segments.begin(), segments.begin() + 1);
  EXPECT_FALSE(vp_direction_covariance(K, one, d, 0.5, &few));

  const double floor = 0.2 * M_PI / 180.0;
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
  Eigen::Matrix3d M;
  ASSERT_TRUE(vp_measurement_covariance(K, segments, d, 0.5, floor, &M));
  EXPECT_LT((M - (C + floor * floor * P)).norm(), 1e-15);
  EXPECT_FALSE(vp_measurement_covariance(K, one, d, 0.5, floor, &M));
  EXPECT_LT((M - floor * floor * P).norm(), 1e-15);
}

}  // namespace hybrid_vo
