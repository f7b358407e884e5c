// One scale over a window of monocular keyframes: random chains whose links' lengths are given
// wrong, the points tracked across them; noiseless (the exact lengths and depths), noisy (an
// honest covariance), with outliers (robust), under another gauge (the same ratios), degenerate
// and bad input (a clean failure).
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include "hybrid_vo/estimation/two_view_depth.h"
#include "hybrid_vo/estimation/window_scale.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

struct Window {
  std::vector<RelativePose> truth;  // the links as they are
  std::vector<RelativePose> given;  // their lengths wrong on the free links
  std::vector<double> factor;       // truth length / given length per link
  std::vector<WindowPoint> points;  // noiseless sightings
  std::vector<double> rho;          // true inverse depth of each point in its anchor
  std::vector<Eigen::Vector3d> X;   // the points in camera 0
};

// A camera moving 0.3-1 units between keyframes, mostly ahead and sideways, turning up to 6
// degrees; points 2-20 units in front of camera 0. Each point is anchored in a random camera and
// seen in the next `span` ones while it stays in a 70-degree field of view. Link 0 is the gauge:
// given right; the others off by a factor of e^N(0, 0.25).
Window random_window(std::mt19937* rng, int links, int points, int max_span) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(2.0, 20.0);
  std::normal_distribution<double> log_error(0.0, 0.25);
  Window w;
  std::vector<Eigen::Matrix3d> R_c0(1, Eigen::Matrix3d::Identity());  // X_c = R_c0 X_0 + t_c0
  std::vector<Eigen::Vector3d> t_c0(1, Eigen::Vector3d::Zero());
  for (int j = 0; j < links; ++j) {
    const Eigen::Matrix3d R =
        rotation_about(Eigen::Vector3d(u(*rng), u(*rng), u(*rng)).normalized(),
                       6.0 * M_PI / 180.0 * std::abs(u(*rng)));
    const Eigen::Vector3d t =
        (0.65 + 0.35 * u(*rng)) *
        Eigen::Vector3d(0.6 * u(*rng), 0.2 * u(*rng), -1.0 + 0.3 * u(*rng)).normalized();
    w.truth.emplace_back(R, t);
    const double f = j == 0 ? 1.0 : std::exp(log_error(*rng));
    w.factor.push_back(f);
    w.given.emplace_back(R, t / f);
    R_c0.push_back(R * R_c0.back());
    t_c0.push_back(R * t_c0.back() + t);
  }
  std::uniform_int_distribution<int> anchor_of(0, links - 1);
  int tries = 0;
  while (static_cast<int>(w.points.size()) < points && ++tries < 100000) {
    const int a = anchor_of(*rng);
    const double z = depth(*rng);
    const Eigen::Vector3d Xa(0.6 * z * u(*rng), 0.45 * z * u(*rng), z);
    const Eigen::Vector3d X0 = R_c0[a].transpose() * (Xa - t_c0[a]);
    WindowPoint p;
    p.anchor = a;
    p.x_anchor = Xa.head<2>() / Xa.z();
    const int span = std::uniform_int_distribution<int>(1, max_span)(*rng);
    for (int c = a + 1; c <= std::min(links, a + span); ++c) {
      const Eigen::Vector3d Xc = R_c0[c] * X0 + t_c0[c];
      if (Xc.z() < 1.0 || (Xc.head<2>() / Xc.z()).cwiseAbs().maxCoeff() > 0.7) break;
      p.seen.emplace_back(c, Xc.head<2>() / Xc.z());
    }
    if (p.seen.empty()) continue;
    w.points.push_back(p);
    w.rho.push_back(1.0 / Xa.z());
    w.X.push_back(X0);
  }
  return w;
}

std::vector<char> gauge_first(int links) {
  std::vector<char> fixed(links, 0);
  fixed[0] = 1;
  return fixed;
}

TEST(WindowScale, NoiselessWindowsGiveTheExactLengthsAndDepths) {
  std::mt19937 rng(1);
  for (int k = 0; k < 50; ++k) {
    const int links = 2 + k % 4;
    const Window w = random_window(&rng, links, 150, 4);
    const WindowScaleEstimate e = estimate_window_scales(w.given, gauge_first(links), w.points);
    ASSERT_TRUE(e.ok) << k;
    ASSERT_EQ(static_cast<int>(e.scales.size()), links);
    EXPECT_EQ(e.scales[0], 1.0);
    for (int j = 0; j < links; ++j) EXPECT_NEAR(e.scales[j], w.factor[j], 1e-7 * w.factor[j]) << k;
    for (size_t i = 0; i < w.points.size(); ++i) {
      if (!(e.rho[i] > 0.0)) continue;
      EXPECT_NEAR(e.rho[i], w.rho[i], 1e-7 * w.rho[i]) << k << " " << i;
    }
    EXPECT_GE(e.points_used, 140) << k;
    EXPECT_EQ(e.inliers, e.points_used) << k;
  }
}

// Round trip: the fitted depth of a point, carried along the fitted chain into its last camera,
// is where that camera sees it (the depths a keyframe hands on).
TEST(WindowScale, FittedDepthsCarriedAlongTheChainMatchTheTruth) {
  std::mt19937 rng(2);
  const Window w = random_window(&rng, 4, 200, 4);
  const WindowScaleEstimate e = estimate_window_scales(w.given, gauge_first(4), w.points);
  ASSERT_TRUE(e.ok);
  int checked = 0;
  for (size_t i = 0; i < w.points.size(); ++i) {
    const WindowPoint& p = w.points[i];
    if (!(e.rho[i] > 0.0)) continue;
    // Link by link, each time along the ray where the next camera sees it (the sightings follow
    // each other).
    InverseDepth d{true, e.rho[i], 1e-3 * e.rho[i]};
    Eigen::Vector2d x = p.x_anchor;
    for (const auto& [camera, seen] : p.seen) {
      const RelativePose& g = w.given[camera - 1];
      d = transfer_inverse_depth(g.R, g.t * e.scales[camera - 1], x, d);
      ASSERT_TRUE(d.ok);
      x = seen;
    }
    const Eigen::Vector3d X0 = w.X[i];
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    for (int link = 0; link < p.seen.back().first; ++link) {
      R = w.truth[link].R * R;
      t = w.truth[link].R * t + w.truth[link].t;
    }
    EXPECT_NEAR(d.rho, 1.0 / (R * X0 + t).z(), 1e-7 * d.rho) << i;
    ++checked;
  }
  EXPECT_GT(checked, 150);
}

// Fixing another link only changes the unit: every ratio of lengths stays.
TEST(WindowScale, AnotherGaugeGivesTheSameRatios) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1e-3);
  Window w = random_window(&rng, 4, 250, 4);
  for (WindowPoint& p : w.points)
    for (auto& s : p.seen) s.second += Eigen::Vector2d(noise(rng), noise(rng));
  const WindowScaleEstimate first = estimate_window_scales(w.given, gauge_first(4), w.points);
  std::vector<char> last(4, 0);
  last[3] = 1;
  const WindowScaleEstimate other = estimate_window_scales(w.given, last, w.points);
  ASSERT_TRUE(first.ok);
  ASSERT_TRUE(other.ok);
  EXPECT_EQ(other.scales[3], 1.0);
  for (int j = 0; j < 4; ++j)
    EXPECT_NEAR(other.scales[j] / other.scales[0], first.scales[j] / first.scales[0], 1e-6) << j;
}

// With pixel noise in every image (the anchors' too, which the model takes as exact) the
// log-scales' errors under their covariance are chi-square with as many dof as free links.
TEST(WindowScale, NoisyWindowsHaveAnHonestCovariance) {
  std::mt19937 rng(4);
  const double sigma = 1.0 / 500.0;
  std::normal_distribution<double> noise(0.0, sigma);
  WindowScaleOptions options;
  options.point_sigma = sigma;
  std::vector<double> nees, errors;
  int dof = 0;
  for (int k = 0; k < 300; ++k) {
    const int links = 3;
    Window w = random_window(&rng, links, 120, 3);
    for (WindowPoint& p : w.points) {
      p.x_anchor += Eigen::Vector2d(noise(rng), noise(rng));
      for (auto& s : p.seen) s.second += Eigen::Vector2d(noise(rng), noise(rng));
    }
    const WindowScaleEstimate e =
        estimate_window_scales(w.given, gauge_first(links), w.points, options);
    if (!e.ok) continue;
    dof = links - 1;
    Eigen::VectorXd err(dof);
    for (int j = 1; j < links; ++j) err(j - 1) = std::log(e.scales[j] / w.factor[j]);
    const Eigen::MatrixXd C = e.log_covariance.bottomRightCorner(dof, dof);
    nees.push_back(err.dot(C.ldlt().solve(err)));
    errors.push_back(err.cwiseAbs().maxCoeff());
  }
  ASSERT_GT(nees.size(), 250u);
  std::sort(nees.begin(), nees.end());
  const double median = nees[nees.size() / 2];
  const double inside = static_cast<double>(std::count_if(nees.begin(), nees.end(),
                                                          [](double v) { return v < 5.991; })) /
                        nees.size();
  // chi-square with 2 dof: median 1.386, 95 % below 5.991 (measured: 1.80, 94 %; with the anchor
  // taken as exact 2.21, 86 %).
  EXPECT_GT(median, 0.7) << median;
  EXPECT_LT(median, 2.6) << median;
  EXPECT_GT(inside, 0.88) << inside;
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.05);  // a few percent at 1 px
  RecordProperty("nees_median", std::to_string(median));
  RecordProperty("inside_95", std::to_string(inside));
}

// A sixth of the sightings are wrong matches anywhere in the image: the Cauchy loss leaves the
// lengths within their (honest) sigmas, a percent or two here, and marks most of those points.
TEST(WindowScale, WrongMatchesDoNotMoveTheLengths) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> anywhere(-0.6, 0.6), u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1e-3);
  WindowScaleOptions options;
  options.point_sigma = 1e-3;
  for (int k = 0; k < 20; ++k) {
    Window w = random_window(&rng, 3, 200, 3);
    std::vector<char> wrong(w.points.size(), 0);
    for (size_t i = 0; i < w.points.size(); ++i)
      for (auto& s : w.points[i].seen) {
        s.second += Eigen::Vector2d(noise(rng), noise(rng));
        if (u(rng) < 1.0 / 6.0) {
          s.second = Eigen::Vector2d(anywhere(rng), anywhere(rng));
          wrong[i] = 1;
        }
      }
    const WindowScaleEstimate e =
        estimate_window_scales(w.given, gauge_first(3), w.points, options);
    ASSERT_TRUE(e.ok) << k;
    for (int j = 1; j < 3; ++j) {
      const double sigma = std::sqrt(e.log_covariance(j, j));
      EXPECT_LT(sigma, 0.05) << k << " " << j;
      EXPECT_LT(std::abs(std::log(e.scales[j] / w.factor[j])), 4.0 * sigma) << k << " " << j;
    }
    int wrong_flagged = 0, wrong_total = 0;
    for (size_t i = 0; i < w.points.size(); ++i)
      if (wrong[i] && e.rho[i] > 0.0) {
        ++wrong_total;
        wrong_flagged += !e.inlier[i];
      }
    EXPECT_GT(wrong_flagged, 0.7 * wrong_total) << k;
  }
}

TEST(WindowScale, AllLinksFixedTriangulatesTheDepthsAcrossTheWindow) {
  std::mt19937 rng(6);
  const Window w = random_window(&rng, 3, 100, 3);
  const WindowScaleEstimate e = estimate_window_scales(w.truth, std::vector<char>(3, 1), w.points);
  ASSERT_TRUE(e.ok);
  int checked = 0;
  for (size_t i = 0; i < w.points.size(); ++i) {
    if (!(e.rho[i] > 0.0)) continue;
    EXPECT_NEAR(e.rho[i], w.rho[i], 1e-8 * w.rho[i]);
    ++checked;
  }
  EXPECT_GT(checked, 90);
}

TEST(WindowScale, DegenerateAndBadInputFailCleanly) {
  std::mt19937 rng(7);
  const Window w = random_window(&rng, 3, 150, 3);
  const std::vector<char> fixed = gauge_first(3);
  ASSERT_TRUE(estimate_window_scales(w.given, fixed, w.points).ok);
  // Points seen by two cameras only tie no two lengths together.
  const Window pairs = random_window(&rng, 3, 150, 1);
  EXPECT_FALSE(estimate_window_scales(pairs.given, fixed, pairs.points).ok);
  // No gauge, no links, a mismatched mask, no points.
  EXPECT_FALSE(estimate_window_scales(w.given, std::vector<char>(3, 0), w.points).ok);
  EXPECT_FALSE(estimate_window_scales({}, {}, w.points).ok);
  EXPECT_FALSE(estimate_window_scales(w.given, gauge_first(2), w.points).ok);
  EXPECT_FALSE(estimate_window_scales(w.given, fixed, {}).ok);
  // Not finite.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<RelativePose> links = w.given;
  links[1].t.x() = nan;
  EXPECT_FALSE(estimate_window_scales(links, fixed, w.points).ok);
  std::vector<WindowPoint> points = w.points;
  points[3].seen[0].second.y() = nan;
  EXPECT_FALSE(estimate_window_scales(w.given, fixed, points).ok);
  points = w.points;
  points[5].rho = INFINITY;
  EXPECT_FALSE(estimate_window_scales(w.given, fixed, points).ok);
  // A camera out of the chain, or a sighting before its anchor.
  points = w.points;
  points[0].seen.emplace_back(4, Eigen::Vector2d::Zero());
  EXPECT_FALSE(estimate_window_scales(w.given, fixed, points).ok);
  points = w.points;
  points[0].seen.emplace_back(points[0].anchor, Eigen::Vector2d::Zero());
  EXPECT_FALSE(estimate_window_scales(w.given, fixed, points).ok);
  WindowScaleOptions bad;
  bad.point_sigma = 0.0;
  EXPECT_FALSE(estimate_window_scales(w.given, fixed, w.points, bad).ok);
  // A camera that only turns sees every point where its rotation puts it: no depth, no length.
  Window turning = w;
  for (WindowPoint& p : turning.points) {
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    int camera = p.anchor;
    for (auto& s : p.seen) {
      for (; camera < s.first; ++camera) R = w.given[camera].R * R;
      const Eigen::Vector3d ray = R * homogeneous(p.x_anchor);
      s.second = ray.head<2>() / ray.z();
    }
  }
  EXPECT_FALSE(estimate_window_scales(w.given, fixed, turning.points).ok);
}

}  // namespace
}  // namespace hybrid_vo
