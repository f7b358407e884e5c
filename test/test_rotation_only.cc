// Rotation-only pairs and the choice between them and a full motion: random scenes seen by a
// camera that turns about its centre (exact, noisy, with outliers; points, segments or VPs alone),
// the covariance against the error over many noisy instances, degenerate and invalid input, and
// GRIC at the boundary (a translation of 0, 0.1 % and 1 % of the scene's depth).
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "hybrid_vo/estimation/motion_model_selection.h"
#include "hybrid_vo/estimation/rotation_only.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose_error.h"

namespace {

using namespace hybrid_vo;

const PinholeCamera kCamera(500.0, 500.0, 320.0, 240.0, 640, 480);
constexpr double kDeg = M_PI / 180.0;

Eigen::Matrix3d random_rotation(std::mt19937_64& rng, double max_deg) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> angle(0.0, max_deg * kDeg);
  const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  return Eigen::AngleAxisd(angle(rng), axis).toRotationMatrix();
}

// Pixel of a camera-frame point, or false outside the image.
bool project(const Eigen::Vector3d& X, Eigen::Vector2d* x) {
  if (X.z() <= 0.1) return false;
  *x = kCamera.denormalize(X.head<2>() / X.z());
  return kCamera.in_image(*x);
}

struct Scene {
  TwoViewMatches matches;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};

// Points at 2-10 m seen from two cameras, X2 = R X1 + t, with pixel noise and a share of random
// outliers; segments between pairs of such points; VPs of three orthogonal directions.
Scene make_scene(std::mt19937_64& rng, int num_points, int num_lines, bool vps, double noise_px,
                 double outliers, const Eigen::Vector3d& t = Eigen::Vector3d::Zero(),
                 double max_rotation_deg = 10.0) {
  Scene s;
  s.R = random_rotation(rng, max_rotation_deg);
  s.t = t;
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(2.0, 10.0), unit(0.0, 1.0);
  std::uniform_real_distribution<double> px(0.0, 640.0), py(0.0, 480.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  const auto random_point = [&]() {
    const double z = depth(rng);
    return Eigen::Vector3d(u(rng) * 0.6 * z, u(rng) * 0.45 * z, z);
  };
  while (static_cast<int>(s.matches.points.size()) < num_points) {
    const Eigen::Vector3d X = random_point();
    PointMatch m;
    if (!project(X, &m.x1) || !project(s.R * X + t, &m.x2)) continue;
    m.x1 += Eigen::Vector2d(noise(rng), noise(rng));
    m.x2 += Eigen::Vector2d(noise(rng), noise(rng));
    if (unit(rng) < outliers) m.x2 = Eigen::Vector2d(px(rng), py(rng));
    s.matches.points.push_back(m);
  }
  while (static_cast<int>(s.matches.lines.size()) < num_lines) {
    const Eigen::Vector3d A = random_point(), B = random_point();
    LineMatch m;
    if (!project(A, &m.s1.p1) || !project(B, &m.s1.p2) || !project(s.R * A + t, &m.s2.p1) ||
        !project(s.R * B + t, &m.s2.p2) || m.s1.length() < 40.0)
      continue;
    for (Eigen::Vector2d* p : {&m.s1.p1, &m.s1.p2, &m.s2.p1, &m.s2.p2})
      *p += Eigen::Vector2d(noise(rng), noise(rng));
    s.matches.lines.push_back(m);
  }
  if (vps) {
    const Eigen::Matrix3d axes = random_rotation(rng, 180.0);
    for (int k = 0; k < 3; ++k) {
      VpMatch v;
      v.d1 = axes.col(k);
      v.d2 = -(s.R * axes.col(k));  // the sign unknown, as the detector gives it
      s.matches.vps.push_back(v);
    }
  }
  return s;
}

double rotation_error_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return rotation_error(a, b) / kDeg;
}

TEST(RotationOnly, NoiselessPointsGiveTheRotation) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const Scene s = make_scene(rng, 60, 0, false, 0.0, 0.0);
    const RotationOnlyEstimate est = estimate_rotation_only(kCamera, kCamera, s.matches);
    ASSERT_TRUE(est.ok) << trial;
    EXPECT_LT(rotation_error_deg(est.R, s.R), 1e-8) << trial;
    EXPECT_EQ(est.num_point_inliers, 60);
    EXPECT_LT(est.parallax_px, 1e-6);
    EXPECT_TRUE(est.covariance_valid);
  }
}

TEST(RotationOnly, SegmentsAloneOrVpsAloneGiveTheRotation) {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 20; ++trial) {
    const Scene lines = make_scene(rng, 0, 12, false, 0.0, 0.0);
    const RotationOnlyEstimate a = estimate_rotation_only(kCamera, kCamera, lines.matches);
    ASSERT_TRUE(a.ok) << trial;
    EXPECT_LT(rotation_error_deg(a.R, lines.R), 1e-6) << trial;
    EXPECT_EQ(a.parallax_px, -1.0);  // no points: the parallax is unknown
    const Scene vps = make_scene(rng, 0, 0, true, 0.0, 0.0);
    const RotationOnlyEstimate b = estimate_rotation_only(kCamera, kCamera, vps.matches);
    ASSERT_TRUE(b.ok) << trial;
    EXPECT_LT(rotation_error_deg(b.R, vps.R), 1e-6) << trial;
    EXPECT_EQ(b.num_vp_inliers, 3);
  }
}

TEST(RotationOnly, OutliersAreLeftOut) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Scene s = make_scene(rng, 200, 20, true, 0.5, 0.4);
    const RotationOnlyEstimate est = estimate_rotation_only(kCamera, kCamera, s.matches);
    ASSERT_TRUE(est.ok) << trial;
    EXPECT_LT(rotation_error_deg(est.R, s.R), 0.05) << trial;
    EXPECT_GT(est.num_point_inliers, 100);
    EXPECT_LT(est.num_point_inliers, 150);
  }
}

// Over many noisy instances the error falls inside the covariance's 95 % ellipsoid about as often
// as it should (3 dof: 7.81); the points number less than independent_points, so no weighting.
TEST(RotationOnly, TheCovarianceHoldsTheError) {
  std::mt19937_64 rng(4);
  int inside = 0, trials = 300;
  std::vector<double> nees;
  for (int trial = 0; trial < trials; ++trial) {
    const Scene s = make_scene(rng, 100, 15, true, 0.7, 0.1);
    const RotationOnlyEstimate est = estimate_rotation_only(kCamera, kCamera, s.matches);
    ASSERT_TRUE(est.ok);
    const Eigen::AngleAxisd e(Eigen::Matrix3d(est.R * s.R.transpose()));
    const Eigen::Vector3d w = e.angle() * e.axis();
    const double value = w.dot(est.covariance.inverse() * w);
    nees.push_back(value);
    inside += value < 7.81;
  }
  std::sort(nees.begin(), nees.end());
  EXPECT_GT(nees[nees.size() / 2], 2.37 / 1.6);
  EXPECT_LT(nees[nees.size() / 2], 2.37 * 1.6);
  EXPECT_GT(inside, 0.88 * trials);
}

TEST(RotationOnly, TheParallaxIsWhatTheRotationLeaves) {
  std::mt19937_64 rng(5);
  // 30 cm sideways at 2-10 m: tens of pixels of parallax, which the rotation cannot explain.
  const Scene s = make_scene(rng, 200, 0, false, 0.3, 0.0, Eigen::Vector3d(0.3, 0.0, 0.0), 5.0);
  const RotationOnlyEstimate est = estimate_rotation_only(kCamera, kCamera, s.matches);
  EXPECT_GT(est.parallax_px, 5.0);
}

TEST(RotationOnly, BadInputGivesNoRotation) {
  TwoViewMatches empty;
  EXPECT_FALSE(estimate_rotation_only(kCamera, kCamera, empty).ok);
  TwoViewMatches one;
  one.points.push_back({Eigen::Vector2d(100, 100), Eigen::Vector2d(110, 100)});
  EXPECT_FALSE(estimate_rotation_only(kCamera, kCamera, one).ok);
  std::mt19937_64 rng(6);
  Scene s = make_scene(rng, 30, 5, true, 0.3, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s.matches.points[0].x1.x() = nan;
  s.matches.lines[0].s2.p1.y() = nan;
  s.matches.vps[0].d1 = Eigen::Vector3d(nan, 0.0, 1.0);
  const RotationOnlyEstimate est = estimate_rotation_only(kCamera, kCamera, s.matches);
  ASSERT_TRUE(est.ok);
  EXPECT_FALSE(est.point_inliers[0]);
  EXPECT_FALSE(est.line_inliers[0]);
  EXPECT_FALSE(est.vp_inliers[0]);
  EXPECT_TRUE(all_finite(est.R));
  EXPECT_TRUE(all_finite(est.covariance));
  PinholeCamera invalid = kCamera;
  invalid.fx = nan;
  EXPECT_FALSE(estimate_rotation_only(invalid, kCamera, s.matches).ok);
  // All points at one pixel: the rotation about it is not fixed.
  TwoViewMatches same;
  for (int i = 0; i < 20; ++i) same.points.push_back({Eigen::Vector2d(300, 200), Eigen::Vector2d(310, 200)});
  const RotationOnlyEstimate degenerate = estimate_rotation_only(kCamera, kCamera, same);
  EXPECT_FALSE(degenerate.ok);
  EXPECT_TRUE(all_finite(degenerate.R));
}

// The full motion's answer for the test below: the true pose (what a converged estimator gives).
MotionModelScores choose(const Scene& s, double noise_px) {
  const RotationOnlyEstimate rotation = estimate_rotation_only(kCamera, kCamera, s.matches);
  RelativePose full{s.R, s.t.norm() > 0.0 ? Eigen::Vector3d(s.t.normalized())
                                          : Eigen::Vector3d(1.0, 0.0, 0.0)};
  return select_motion_model(kCamera, kCamera, s.matches.points, {}, full, rotation.R, noise_px);
}

// Depths of 2-10 m (6 m on average): translations of 0, 0.1 % (6 mm) and 1 % (6 cm) of it,
// sideways, with 0.5 px of noise over 300 points.
TEST(MotionModelSelection, ChoosesTheRotationOnlyWhereTheTranslationIsNotSeen) {
  std::mt19937_64 rng(7);
  int still = 0, small = 0, large = 0;
  for (int trial = 0; trial < 20; ++trial) {
    still += choose(make_scene(rng, 300, 0, false, 0.5, 0.0), 0.5).rotation_only;
    small += choose(make_scene(rng, 300, 0, false, 0.5, 0.0, Eigen::Vector3d(0.006, 0, 0)), 0.5)
                 .rotation_only;
    large += choose(make_scene(rng, 300, 0, false, 0.5, 0.0, Eigen::Vector3d(0.06, 0, 0)), 0.5)
                 .rotation_only;
  }
  EXPECT_EQ(still, 20);
  EXPECT_GE(small, 15);  // about half a pixel of parallax at most: within the noise
  EXPECT_EQ(large, 0);   // 3-15 px
}

// Tracked points are not equally precise: two in five of them three times noisier. A robust sigma
// would read their squares as structure the rotation misses; the turn in place stays one.
TEST(MotionModelSelection, UnequalNoiseIsNoTranslation) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> noise(0.0, 0.85);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int still = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Scene s = make_scene(rng, 300, 0, false, 0.3, 0.0);
    for (PointMatch& m : s.matches.points)
      if (unit(rng) < 0.4) m.x2 += Eigen::Vector2d(noise(rng), noise(rng));
    still += choose(s, 0.3).rotation_only;
  }
  EXPECT_GE(still, 19);
}

TEST(MotionModelSelection, WithoutNoiseOrPointsTheFullModelStays) {
  std::mt19937_64 rng(8);
  const Scene s = make_scene(rng, 50, 0, false, 0.5, 0.0);
  EXPECT_FALSE(choose(s, 0.0).rotation_only);
  EXPECT_FALSE(choose(s, std::numeric_limits<double>::quiet_NaN()).rotation_only);
  EXPECT_FALSE(select_motion_model(kCamera, kCamera, {}, {}, RelativePose(),
                                   Eigen::Matrix3d::Identity(), 0.5)
                   .rotation_only);
}

}  // namespace
