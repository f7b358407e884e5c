// The ground-truth check of the pair evaluation (include/hybrid_vo/evaluation/ground_truth_check.h)
// and the core's sampson_error_px it rests on (include/hybrid_vo/geometry/epipolar_error.h).

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/evaluation/ground_truth_check.h"

namespace hybrid_vo {
namespace evaluation {
namespace {

struct Scene {
  PinholeCamera camera1{500.0, 520.0, 320.0, 240.0, 640, 480};
  PinholeCamera camera2{700.0, 690.0, 300.0, 250.0, 640, 480};
  RelativePose pose;
  std::vector<PointMatch> matches;
};

Scene make_scene(int n, uint64_t seed) {
  Scene s;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, 1.0, -0.2).normalized();
  s.pose.R = Eigen::AngleAxisd(0.2, axis).toRotationMatrix();
  s.pose.t = Eigen::Vector3d(1.0, 0.1, 0.3).normalized();
  while (static_cast<int>(s.matches.size()) < n) {
    const Eigen::Vector3d X(2.0 * u(rng), 2.0 * u(rng), 5.0 + 2.0 * u(rng));
    const Eigen::Vector3d Y = s.pose.apply(X);
    if (Y.z() <= 0.1) continue;
    PointMatch m;
    m.x1 = s.camera1.denormalize(X.hnormalized());
    m.x2 = s.camera2.denormalize(Y.hnormalized());
    s.matches.push_back(m);
  }
  return s;
}

// The unit normal in image 2 of the epipolar line of x1.
Eigen::Vector2d epipolar_normal(const Scene& s, const PointMatch& m) {
  const Eigen::Matrix3d F =
      s.camera2.K().inverse().transpose() * s.pose.essential() * s.camera1.K().inverse();
  return (F * m.x1.homogeneous()).head<2>().normalized();
}

TEST(GroundTruthCheck, ExactMatchesHaveNoError) {
  const Scene s = make_scene(50, 1);
  for (const PointMatch& m : s.matches)
    EXPECT_LT(sampson_error_px(s.camera1, s.camera2, s.pose, m.x1, m.x2), 1e-9);
  EXPECT_LT(median_sampson_px(s.camera1, s.camera2, s.pose, s.matches), 1e-9);
}

TEST(GroundTruthCheck, ErrorIsInPixels) {
  // x2 moved off its epipolar line by d pixels: the Sampson error, a first-order geometric error
  // that may share the correction between both points, is at most d and a good part of it.
  const Scene s = make_scene(30, 2);
  for (const double d : {0.5, 2.0, 8.0}) {
    for (const PointMatch& exact : s.matches) {
      PointMatch m = exact;
      m.x2 += d * epipolar_normal(s, exact);
      const double e = sampson_error_px(s.camera1, s.camera2, s.pose, m.x1, m.x2);
      EXPECT_LE(e, d * (1.0 + 1e-6));
      EXPECT_GE(e, 0.4 * d);
    }
  }
  // The same scene at twice the resolution has twice the error.
  Scene big = s;
  for (PinholeCamera* c : {&big.camera1, &big.camera2}) {
    c->fx *= 2.0, c->fy *= 2.0, c->cx *= 2.0, c->cy *= 2.0;
  }
  for (size_t i = 0; i < s.matches.size(); ++i) {
    PointMatch m = s.matches[i];
    m.x2 += 1.5 * epipolar_normal(s, s.matches[i]);
    PointMatch m2{2.0 * m.x1, 2.0 * m.x2};
    EXPECT_NEAR(sampson_error_px(big.camera1, big.camera2, big.pose, m2.x1, m2.x2),
                2.0 * sampson_error_px(s.camera1, s.camera2, s.pose, m.x1, m.x2), 1e-9);
  }
}

TEST(GroundTruthCheck, AWrongPoseFitsWorse) {
  Scene s = make_scene(200, 3);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (PointMatch& m : s.matches) m.x2 += Eigen::Vector2d(noise(rng), noise(rng));
  const double right = median_sampson_px(s.camera1, s.camera2, s.pose, s.matches);
  RelativePose wrong = s.pose;
  wrong.R = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix() * wrong.R;
  const double off = median_sampson_px(s.camera1, s.camera2, wrong, s.matches);
  EXPECT_GT(right, 0.1);
  EXPECT_LT(right, 0.5);
  EXPECT_GT(off, 2.0 * right);
}

TEST(GroundTruthCheck, MaskSelectsAndBadInputIsNan) {
  Scene s = make_scene(5, 5);
  s.matches[0].x2 += Eigen::Vector2d(30.0, -40.0);
  s.matches[1].x2 += Eigen::Vector2d(-30.0, 40.0);
  s.matches[2].x2 += Eigen::Vector2d(30.0, 40.0);
  const std::vector<char> good = {0, 0, 0, 1, 1};
  EXPECT_GT(median_sampson_px(s.camera1, s.camera2, s.pose, s.matches), 1.0);
  EXPECT_LT(median_sampson_px(s.camera1, s.camera2, s.pose, s.matches, good), 1e-9);
  EXPECT_TRUE(std::isnan(median_sampson_px(s.camera1, s.camera2, s.pose, s.matches, {1, 1})));
  EXPECT_TRUE(std::isnan(median_sampson_px(s.camera1, s.camera2, s.pose, s.matches,
                                           {0, 0, 0, 0, 0})));
  EXPECT_TRUE(std::isnan(median_sampson_px(s.camera1, s.camera2, s.pose, {})));
  RelativePose rotation_only = s.pose;
  rotation_only.t.setZero();
  const PointMatch& m = s.matches[3];
  EXPECT_TRUE(std::isnan(sampson_error_px(s.camera1, s.camera2, rotation_only, m.x1, m.x2)));
  PointMatch bad = s.matches[3];
  bad.x1.x() = NAN;
  EXPECT_TRUE(std::isnan(sampson_error_px(s.camera1, s.camera2, s.pose, bad.x1, bad.x2)));
  // A non-finite match is left out of the median, not counted as zero or infinite.
  std::vector<PointMatch> with_bad = {s.matches[3], bad, s.matches[4]};
  EXPECT_LT(median_sampson_px(s.camera1, s.camera2, s.pose, with_bad), 1e-9);
}

TEST(GroundTruthCheck, TruncatedCostCountsOutliersOnceAndInliersByTheirError) {
  Scene s = make_scene(8, 6);
  EXPECT_LT(truncated_sampson_cost(s.camera1, s.camera2, s.pose, s.matches, 1.0), 1e-18);
  // Half the matches far off: each costs 1, the rest 0.
  std::vector<PointMatch> mixed = s.matches;
  for (int i = 0; i < 4; ++i) mixed[i].x2 += 50.0 * epipolar_normal(s, s.matches[i]);
  EXPECT_NEAR(truncated_sampson_cost(s.camera1, s.camera2, s.pose, mixed, 1.0), 0.5, 1e-12);
  // An inlier costs its squared error over the squared threshold.
  std::vector<PointMatch> one = {s.matches[5]};
  one[0].x2 += 0.8 * epipolar_normal(s, s.matches[5]);
  const double e = sampson_error_px(s.camera1, s.camera2, s.pose, one[0].x1, one[0].x2);
  EXPECT_NEAR(truncated_sampson_cost(s.camera1, s.camera2, s.pose, one, 2.0), e * e / 4.0, 1e-12);
  // No translation explains no parallax: every match counts as an outlier.
  RelativePose rotation_only = s.pose;
  rotation_only.t.setZero();
  EXPECT_EQ(truncated_sampson_cost(s.camera1, s.camera2, rotation_only, s.matches, 1.0), 1.0);
  EXPECT_TRUE(std::isnan(truncated_sampson_cost(s.camera1, s.camera2, s.pose, {}, 1.0)));
  EXPECT_TRUE(std::isnan(truncated_sampson_cost(s.camera1, s.camera2, s.pose, s.matches, 0.0)));
  EXPECT_TRUE(std::isnan(truncated_sampson_cost(s.camera1, s.camera2, s.pose, s.matches, NAN)));
}

}  // namespace
}  // namespace evaluation
}  // namespace hybrid_vo
