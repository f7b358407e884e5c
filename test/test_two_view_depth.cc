// A monocular keyframe's inverse depths: triangulated from random pairs (exact without noise,
// their sigma honest with noise), moved into the next camera, fused; degenerate and bad input.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/estimation/two_view_depth.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

struct Instance {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  Eigen::Vector3d X1;  // camera 1
  Eigen::Vector3d X2() const { return R * X1 + t; }
};

// A pair X2 = R X1 + t, 0-10 degrees apart with a baseline of 0.2-1, and a point 2-20 in front of
// both cameras within a 60-degree field of view.
Instance random_instance(std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(2.0, 20.0);
  Instance in;
  in.R = rotation_about(Eigen::Vector3d(u(*rng), u(*rng), u(*rng)).normalized(),
                        10.0 * M_PI / 180.0 * std::abs(u(*rng)));
  in.t = (0.6 + 0.4 * u(*rng)) * Eigen::Vector3d(u(*rng), 0.3 * u(*rng), u(*rng)).normalized();
  do {
    const double z = depth(*rng);
    in.X1 = Eigen::Vector3d(0.5 * z * u(*rng), 0.4 * z * u(*rng), z);
  } while (in.X2().z() < 1.0 || (in.X2().head<2>() / in.X2().z()).norm() > 0.6);
  return in;
}

Eigen::Vector2d project(const Eigen::Vector3d& X) { return X.head<2>() / X.z(); }

TEST(TwoViewDepth, NoiselessPairsGiveTheExactInverseDepth) {
  std::mt19937 rng(1);
  int checked = 0;
  for (int k = 0; k < 500; ++k) {
    const Instance in = random_instance(&rng);
    const InverseDepth d =
        triangulate_inverse_depth(in.R, in.t, project(in.X1), project(in.X2()), 1e-3);
    // Points nearly along t have no parallax; the rest are exact.
    const double parallax = std::acos(in.X1.normalized().dot((in.X1 + in.R.transpose() * in.t).normalized()));
    if (parallax < 1e-3) continue;
    ++checked;
    ASSERT_TRUE(d.ok) << k;
    EXPECT_NEAR(d.rho, 1.0 / in.X2().z(), 1e-9 / in.X2().z()) << k;
    EXPECT_GT(d.sigma, 0.0);
  }
  EXPECT_GT(checked, 450);
}

// With pixel noise of sigma_n in both images, the errors over their declared sigmas have a
// variance near 1 (chi-square with one dof: 95 % within 1.96).
TEST(TwoViewDepth, NoisyPairsHaveAnHonestSigma) {
  std::mt19937 rng(2);
  const double sigma_n = 1.0 / 500.0;
  std::normal_distribution<double> noise(0.0, sigma_n);
  std::vector<double> z;
  for (int k = 0; k < 3000; ++k) {
    const Instance in = random_instance(&rng);
    const Eigen::Vector2d x1 = project(in.X1) + Eigen::Vector2d(noise(rng), noise(rng));
    const Eigen::Vector2d x2 = project(in.X2()) + Eigen::Vector2d(noise(rng), noise(rng));
    const InverseDepth d = triangulate_inverse_depth(in.R, in.t, x1, x2, sigma_n);
    // Well-constrained points only, where first order holds (sigma a tenth of rho at most).
    if (!d.ok || d.sigma > 0.1 * d.rho) continue;
    z.push_back((d.rho - 1.0 / in.X2().z()) / d.sigma);
  }
  ASSERT_GT(z.size(), 1000u);
  int inside = 0;
  double sum2 = 0.0;
  for (const double v : z) {
    inside += std::abs(v) < 1.96;
    sum2 += v * v;
  }
  const double share = static_cast<double>(inside) / z.size();
  EXPECT_GT(share, 0.88);
  EXPECT_LT(share, 0.99);
  EXPECT_NEAR(sum2 / z.size(), 1.0, 0.35);
}

// Round trip: a depth in camera 1 moved into camera 2 is the triangulated depth there, and
// fusing two estimates weighs them by their variances.
TEST(TwoViewDepth, TransferAndFusion) {
  std::mt19937 rng(3);
  for (int k = 0; k < 200; ++k) {
    const Instance in = random_instance(&rng);
    InverseDepth d1;
    d1.ok = true;
    d1.rho = 1.0 / in.X1.z();
    d1.sigma = 0.01 * d1.rho;
    const InverseDepth d2 = transfer_inverse_depth(in.R, in.t, project(in.X1), d1);
    ASSERT_TRUE(d2.ok);
    EXPECT_NEAR(d2.rho, 1.0 / in.X2().z(), 1e-12);
    // First order: a small change of rho1 moves rho2 by the sigma's ratio.
    InverseDepth moved = d1;
    moved.rho += 1e-6;
    const double slope = (transfer_inverse_depth(in.R, in.t, project(in.X1), moved).rho - d2.rho) / 1e-6;
    EXPECT_NEAR(d2.sigma, std::abs(slope) * d1.sigma, 1e-4 * d2.sigma + 1e-15);
  }
  InverseDepth a{true, 1.0, 0.1}, b{true, 2.0, 0.2};
  const InverseDepth f = fuse_inverse_depths(a, b);
  EXPECT_TRUE(f.ok);
  EXPECT_NEAR(f.rho, (1.0 / 0.01 + 2.0 / 0.04) / (1.0 / 0.01 + 1.0 / 0.04), 1e-12);
  EXPECT_NEAR(f.sigma, 1.0 / std::sqrt(1.0 / 0.01 + 1.0 / 0.04), 1e-12);
  EXPECT_EQ(fuse_inverse_depths(InverseDepth{}, b).rho, 2.0);
  EXPECT_EQ(fuse_inverse_depths(a, InverseDepth{}).rho, 1.0);
  EXPECT_FALSE(fuse_inverse_depths(InverseDepth{}, InverseDepth{}).ok);
}

TEST(TwoViewDepth, DegenerateAndBadInputAreNotOk) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d t(1.0, 0.0, 0.0);
  const Eigen::Vector2d x(0.1, 0.05);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // No baseline, no sigma, NaNs.
  EXPECT_FALSE(triangulate_inverse_depth(I, Eigen::Vector3d::Zero(), x, x, 1e-3).ok);
  EXPECT_FALSE(triangulate_inverse_depth(I, t, x, x + Eigen::Vector2d(0.1, 0.0), 0.0).ok);
  EXPECT_FALSE(triangulate_inverse_depth(I, t, Eigen::Vector2d(nan, 0.0), x, 1e-3).ok);
  EXPECT_FALSE(triangulate_inverse_depth(I, Eigen::Vector3d(nan, 0, 0), x, x, 1e-3).ok);
  // A point along the baseline (the epipole) has no parallax.
  const Eigen::Vector3d forward(0.0, 0.0, 1.0);
  EXPECT_FALSE(triangulate_inverse_depth(I, forward, Eigen::Vector2d::Zero(),
                                         Eigen::Vector2d::Zero(), 1e-3).ok);
  // Rays that meet behind the cameras: x2 moved the wrong way for t.
  EXPECT_FALSE(triangulate_inverse_depth(I, t, x, x - Eigen::Vector2d(0.2, 0.0), 1e-3).ok);
  // A transfer behind camera 2, and one from a depth that is not ok.
  const InverseDepth near{true, 1.0, 0.01};
  EXPECT_FALSE(transfer_inverse_depth(I, Eigen::Vector3d(0, 0, -2.0), x, near).ok);
  EXPECT_FALSE(transfer_inverse_depth(I, t, x, InverseDepth{}).ok);
}

}  // namespace
}  // namespace hybrid_vo
