// The synthetic Manhattan scene: sizes, geometry against the truth, outliers, VPs, junctions,
// camera motion and determinism.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/synthetic/manhattan_scene.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

ManhattanSceneOptions noiseless() {
  ManhattanSceneOptions o;
  o.noise_px = 0.0;
  return o;
}

Eigen::Matrix3d fundamental(const ManhattanScene& s) {
  return s.camera2.K_inverse().transpose() * skew(s.truth.t) * s.truth.R * s.camera1.K_inverse();
}

double sampson_px(const Eigen::Matrix3d& F, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  const Eigen::Vector3d Fx1 = F * homogeneous(x1), Ftx2 = F.transpose() * homogeneous(x2);
  return std::abs(homogeneous(x2).dot(Fx1)) /
         std::sqrt(Fx1.head<2>().squaredNorm() + Ftx2.head<2>().squaredNorm());
}

Eigen::Vector2d project(const PinholeCamera& c, const Eigen::Vector3d& X) {
  return c.denormalize(X.head<2>() / X.z());
}

Eigen::Vector3d metric_t(const ManhattanScene& s) { return s.baseline_m * s.truth.t; }

// Unit normal, in camera 1, of the plane through camera 1's centre and segment s1.
Eigen::Vector3d plane1(const ManhattanScene& s, const LineSegment& seg) {
  return (s.camera1.K().transpose() * seg.line()).normalized();
}
Eigen::Vector3d plane2(const ManhattanScene& s, const LineSegment& seg) {
  return (s.camera2.K().transpose() * seg.line()).normalized();  // camera 2
}

double sin_angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return a.normalized().cross(b.normalized()).norm();
}

// Whether the back-projected planes of a segment match meet in a 3D line running along the
// segment's Manhattan direction and lying on its plane. False as well when the planes are nearly
// the same (a line through the epipole), with *degenerate set.
bool consistent_segment(const ManhattanScene& s, int i, double tolerance, bool* degenerate) {
  const LineMatch& m = s.matches.lines[i];
  const Eigen::Vector3d n1 = plane1(s, m.s1);
  const Eigen::Vector3d n2 = plane2(s, m.s2);
  // Plane 2 in camera 1: (R^T n2) . X = -n2 . t.
  const Eigen::Vector3d m2 = s.truth.R.transpose() * n2;
  const Eigen::Vector3d d = n1.cross(m2);
  *degenerate = d.norm() < 1e-4;
  if (*degenerate) return false;
  if (sin_angle(d, s.directions.col(s.line_direction[i])) > tolerance) return false;
  Eigen::Matrix3d A;
  A << n1.transpose(), m2.transpose(), d.normalized().transpose();
  const Eigen::Vector3d X = A.lu().solve(Eigen::Vector3d(0.0, -n2.dot(metric_t(s)), 0.0));
  const ManhattanPlane& p = s.planes[s.line_plane[i]];
  return std::abs(p.normal.dot(X) - p.offset) < tolerance * X.norm();
}

// Whether the infinite lines of a and b meet within `tolerance` px of both segments.
bool meet_within(const LineSegment& a, const LineSegment& b, double tolerance) {
  Eigen::Vector2d x;
  if (!intersect_lines(a.line(), b.line(), &x)) return false;
  auto within = [&](const LineSegment& s) {
    const Eigen::Vector2d u = (s.p2 - s.p1) / s.length();
    const double along = (x - s.p1).dot(u);
    return along >= -tolerance && along <= s.length() + tolerance;
  };
  return within(a) && within(b);
}

int count_junctions(const ManhattanScene& s, double tolerance) {
  int count = 0;
  const int n = static_cast<int>(s.matches.lines.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      if (!s.line_inlier[i] || !s.line_inlier[j]) continue;
      const LineMatch &a = s.matches.lines[i], &b = s.matches.lines[j];
      if (meet_within(a.s1, b.s1, tolerance) && meet_within(a.s2, b.s2, tolerance)) ++count;
    }
  return count;
}

int rounded(double x) { return static_cast<int>(std::lround(x)); }

TEST(ManhattanScene, CountsAndSizesMatchOptions) {
  std::mt19937_64 rng(1);
  for (int num_vps = 0; num_vps <= 3; ++num_vps) {
    ManhattanSceneOptions o;
    o.num_points = 100 + 37 * num_vps;
    o.num_segments = 20 + 11 * num_vps;
    o.num_vps = num_vps;
    o.point_outlier_ratio = 0.1 * num_vps;
    o.line_outlier_ratio = 0.15 * num_vps;
    o.width = 640 + 100 * num_vps;
    o.height = 480;
    o.focal_px = 500.0 + 50.0 * num_vps;
    const ManhattanScene s = generate_manhattan_scene(rng, o);
    const size_t np = o.num_points, ns = o.num_segments;
    EXPECT_EQ(s.matches.points.size(), np);
    EXPECT_EQ(s.point_inlier.size(), np);
    EXPECT_EQ(s.point_plane.size(), np);
    EXPECT_EQ(s.points3d.size(), np);
    EXPECT_EQ(s.matches.lines.size(), ns);
    EXPECT_EQ(s.line_inlier.size(), ns);
    EXPECT_EQ(s.line_plane.size(), ns);
    EXPECT_EQ(s.line_direction.size(), ns);
    EXPECT_EQ(s.matches.line_vp.size(), ns);
    EXPECT_EQ(s.segments3d.size(), ns);
    EXPECT_EQ(s.matches.vps.size(), static_cast<size_t>(num_vps));
    for (const PinholeCamera& c : {s.camera1, s.camera2}) {
      EXPECT_EQ(c.fx, o.focal_px);
      EXPECT_EQ(c.fy, o.focal_px);
      EXPECT_EQ(c.width, o.width);
      EXPECT_EQ(c.height, o.height);
    }
    EXPECT_TRUE(s.planes.size() == 4 || s.planes.size() == 5);
    EXPECT_LT((s.directions.transpose() * s.directions - Eigen::Matrix3d::Identity()).norm(),
              1e-12);
    EXPECT_NEAR(s.directions.determinant(), 1.0, 1e-12);
    for (size_t i = 0; i < ns; ++i) {
      const int d = s.line_direction[i];
      ASSERT_TRUE(d >= 0 && d < 3);
      EXPECT_EQ(s.matches.line_vp[i], d < num_vps ? d : -1);
      ASSERT_TRUE(s.line_plane[i] >= 0 && s.line_plane[i] < static_cast<int>(s.planes.size()));
      EXPECT_NE(s.planes[s.line_plane[i]].direction, d);  // the segment runs inside its plane
    }
    for (int p : s.point_plane) EXPECT_LT(p, static_cast<int>(s.planes.size()));
  }
  // A single wrong segment match borrows a spare segment's image-2 segment.
  ManhattanSceneOptions tiny;
  tiny.num_points = tiny.num_segments = 1;
  tiny.point_outlier_ratio = tiny.line_outlier_ratio = 1.0;
  const ManhattanScene t = generate_manhattan_scene(rng, tiny);
  ASSERT_EQ(t.matches.lines.size(), 1u);
  EXPECT_FALSE(t.line_inlier[0] || t.point_inlier[0]);
  EXPECT_GT((t.matches.lines[0].s2.p1 - t.matches.lines[0].s1.p1).norm(), 1.0);
  ManhattanSceneOptions empty;
  empty.num_points = empty.num_segments = empty.num_vps = 0;
  const ManhattanScene s = generate_manhattan_scene(rng, empty);
  EXPECT_TRUE(s.matches.points.empty() && s.matches.lines.empty() && s.matches.vps.empty());
}

TEST(ManhattanScene, EveryCoordinateIsInsideTheImage) {
  std::mt19937_64 rng(2);
  for (double noise : {0.0, 0.5, 3.0}) {
    ManhattanSceneOptions o;
    o.noise_px = noise;
    o.point_outlier_ratio = 0.3;
    o.line_outlier_ratio = 0.3;
    for (int k = 0; k < 5; ++k) {
      const ManhattanScene s = generate_manhattan_scene(rng, o);
      for (const PointMatch& m : s.matches.points) {
        EXPECT_TRUE(s.camera1.in_image(m.x1)) << m.x1.transpose();
        EXPECT_TRUE(s.camera2.in_image(m.x2)) << m.x2.transpose();
      }
      for (const LineMatch& m : s.matches.lines) {
        for (const Eigen::Vector2d& x : {m.s1.p1, m.s1.p2}) EXPECT_TRUE(s.camera1.in_image(x));
        for (const Eigen::Vector2d& x : {m.s2.p1, m.s2.p2}) EXPECT_TRUE(s.camera2.in_image(x));
      }
    }
  }
}

TEST(ManhattanScene, NoiselessInlierPointsAreExactProjections) {
  std::mt19937_64 rng(3);
  for (int k = 0; k < 5; ++k) {
    const ManhattanScene s = generate_manhattan_scene(rng, noiseless());
    const Eigen::Matrix3d F = fundamental(s);
    for (size_t i = 0; i < s.matches.points.size(); ++i) {
      const PointMatch& m = s.matches.points[i];
      const Eigen::Vector3d X = s.points3d[i], X2 = s.truth.R * X + metric_t(s);
      EXPECT_GE(X.z(), 1.5);
      EXPECT_GE(X2.z(), 1.5);
      EXPECT_LT((project(s.camera1, X) - m.x1).norm(), 1e-9);
      EXPECT_LT((project(s.camera2, X2) - m.x2).norm(), 1e-9);
      EXPECT_LT(sampson_px(F, m.x1, m.x2), 1e-9);
    }
  }
}

TEST(ManhattanScene, SampsonErrorFollowsTheNoiseAndRejectsOutliers) {
  std::mt19937_64 rng(4);
  ManhattanSceneOptions o;
  o.noise_px = 1.0;
  o.point_outlier_ratio = 0.4;
  std::vector<double> inlier_errors;
  int outliers = 0, far_outliers = 0;
  for (int k = 0; k < 4; ++k) {
    const ManhattanScene s = generate_manhattan_scene(rng, o);
    const Eigen::Matrix3d F = fundamental(s);
    for (size_t i = 0; i < s.matches.points.size(); ++i) {
      const double e = sampson_px(F, s.matches.points[i].x1, s.matches.points[i].x2);
      if (s.point_inlier[i]) {
        inlier_errors.push_back(e);
      } else {
        ++outliers;
        if (e > 3.0) ++far_outliers;
      }
    }
  }
  // |N(0, sigma)| has median 0.674 sigma.
  std::nth_element(inlier_errors.begin(), inlier_errors.begin() + inlier_errors.size() / 2,
                   inlier_errors.end());
  const double median = inlier_errors[inlier_errors.size() / 2];
  EXPECT_GT(median, 0.55);
  EXPECT_LT(median, 0.8);
  EXPECT_GT(far_outliers, 0.85 * outliers);
}

TEST(ManhattanScene, OutlierRatiosAreHonoured) {
  std::mt19937_64 rng(5);
  for (double ratio : {0.0, 0.25, 0.5, 0.8, 1.0}) {
    ManhattanSceneOptions o;
    o.num_points = 201;
    o.num_segments = 77;
    o.point_outlier_ratio = ratio;
    o.line_outlier_ratio = 1.0 - ratio;
    const ManhattanScene s = generate_manhattan_scene(rng, o);
    EXPECT_EQ(std::count(s.point_inlier.begin(), s.point_inlier.end(), false),
              rounded(ratio * 201));
    EXPECT_EQ(std::count(s.line_inlier.begin(), s.line_inlier.end(), false),
              rounded((1.0 - ratio) * 77));
  }
}

TEST(ManhattanScene, PlanarPointsLieOnTheirPlanes) {
  std::mt19937_64 rng(6);
  for (double fraction : {0.0, 0.3, 1.0}) {
    ManhattanSceneOptions o = noiseless();
    o.planar_point_fraction = fraction;
    o.point_outlier_ratio = 0.2;
    const ManhattanScene s = generate_manhattan_scene(rng, o);
    int planar_inliers = 0, inliers = 0;
    for (size_t i = 0; i < s.points3d.size(); ++i) {
      const Eigen::Vector3d& X = s.points3d[i];
      inliers += s.point_inlier[i];
      if (s.point_plane[i] >= 0) {
        planar_inliers += s.point_inlier[i];
        const ManhattanPlane& p = s.planes[s.point_plane[i]];
        EXPECT_LT(std::abs(p.normal.dot(X) - p.offset), 1e-9);
      } else {
        for (const ManhattanPlane& p : s.planes)
          EXPECT_GE(std::abs(p.normal.dot(X) - p.offset), 0.25 - 1e-9);
      }
    }
    EXPECT_EQ(planar_inliers, rounded(fraction * inliers));
  }
}

TEST(ManhattanScene, PlanesAreAxisAlignedAndSurroundTheCameras) {
  std::mt19937_64 rng(7);
  for (int k = 0; k < 50; ++k) {
    const ManhattanScene s = generate_manhattan_scene(rng, noiseless());
    const Eigen::Vector3d c2 = s.truth.centre2() * s.baseline_m;
    bool ground = false, back = false;
    for (const ManhattanPlane& p : s.planes) {
      EXPECT_LT((p.normal - s.directions.col(p.direction)).norm(), 1e-15);
      // Camera 2 is on the same side as camera 1 (the origin), at least 0.5 m away.
      EXPECT_GE(std::abs(p.offset), 1.0);
      EXPECT_GE((p.offset - p.normal.dot(c2)) * (p.offset > 0.0 ? 1.0 : -1.0), 0.5);
      ground = ground || (p.direction == 0 && p.offset > 0.0);
      if (p.direction == 1) {
        back = true;
        EXPECT_GE(p.offset, 8.0);
        EXPECT_LE(p.offset, 15.0);
      }
    }
    EXPECT_TRUE(ground && back);
    // Roughly upright: direction 0 within ~15 degrees of camera 1's y axis.
    EXPECT_GT(s.directions.col(0).y(), std::cos(15.0 * kDeg));
  }
}

TEST(ManhattanScene, PointsFillTheImageAndSpanTheDepth) {
  std::mt19937_64 rng(8);
  ManhattanSceneOptions o = noiseless();
  o.num_points = 2000;
  const ManhattanScene s = generate_manhattan_scene(rng, o);
  int quadrant[4] = {0, 0, 0, 0};
  double near = 1e9, far = 0.0;
  for (size_t i = 0; i < s.points3d.size(); ++i) {
    const Eigen::Vector2d& x = s.matches.points[i].x1;
    ++quadrant[(x.x() > o.width / 2) + 2 * (x.y() > o.height / 2)];
    near = std::min(near, s.points3d[i].z());
    far = std::max(far, s.points3d[i].z());
  }
  for (int q : quadrant) EXPECT_GT(q, 0.01 * o.num_points);  // camera 2 may miss some of one
  EXPECT_GE(near, 1.5);
  EXPECT_LT(near, 4.0);
  EXPECT_GT(far, 7.0);
  EXPECT_LT(far, 40.0);
}

TEST(ManhattanScene, NoiselessInlierSegmentsAreConsistentWithTheTruth) {
  std::mt19937_64 rng(9);
  ManhattanSceneOptions o = noiseless();
  o.line_outlier_ratio = 0.3;
  int inliers = 0, inliers_checked = 0, outliers = 0, outliers_rejected = 0;
  for (int k = 0; k < 5; ++k) {
    const ManhattanScene s = generate_manhattan_scene(rng, o);
    for (size_t i = 0; i < s.matches.lines.size(); ++i) {
      bool degenerate = false;
      const bool ok = consistent_segment(s, i, 1e-7, &degenerate);
      if (s.line_inlier[i]) {
        ++inliers;
        if (degenerate) continue;
        ++inliers_checked;
        EXPECT_TRUE(ok) << "scene " << k << " segment " << i;
      } else {
        ++outliers;
        if (!ok) ++outliers_rejected;
      }
      // The image-1 segment is the projection of its 3D segment, which lies on its plane.
      const auto& ends = s.segments3d[i];
      EXPECT_LT((project(s.camera1, ends[0]) - s.matches.lines[i].s1.p1).norm(), 1e-9);
      EXPECT_LT((project(s.camera1, ends[1]) - s.matches.lines[i].s1.p2).norm(), 1e-9);
      EXPECT_LT(sin_angle(ends[1] - ends[0], s.directions.col(s.line_direction[i])), 1e-9);
      const ManhattanPlane& p = s.planes[s.line_plane[i]];
      for (const Eigen::Vector3d& X : ends) EXPECT_LT(std::abs(p.normal.dot(X) - p.offset), 1e-9);
    }
  }
  EXPECT_GT(inliers_checked, 0.9 * inliers);
  EXPECT_GT(outliers_rejected, 0.9 * outliers);
}

TEST(ManhattanScene, SegmentLengthsFollowTheOptions) {
  std::mt19937_64 rng(10);
  ManhattanSceneOptions o = noiseless();
  o.min_segment_px = 60.0;
  o.max_segment_px = 200.0;
  double shortest = 1e9, longest = 0.0;
  for (int k = 0; k < 3; ++k) {
    const ManhattanScene s = generate_manhattan_scene(rng, o);
    for (const LineMatch& m : s.matches.lines) {
      const double l = m.s1.length();
      shortest = std::min(shortest, l);
      longest = std::max(longest, l);
      EXPECT_GE(m.s2.length(), 0.5 * o.min_segment_px - 1e-9);
    }
  }
  // Crossing segments are split around the junction, so the total still follows the options.
  EXPECT_GE(shortest, o.min_segment_px - 1e-6);
  EXPECT_LE(longest, o.max_segment_px + 1e-6);
  EXPECT_LT(shortest, o.min_segment_px + 10.0);
  EXPECT_GT(longest, o.max_segment_px - 10.0);
}

TEST(ManhattanScene, SegmentsPointAtTheirVanishingPoints) {
  std::mt19937_64 rng(11);
  for (double noise : {0.0, 0.5}) {
    ManhattanSceneOptions o;
    o.noise_px = noise;
    o.orient_vps = true;
    std::vector<int> per_direction(3, 0);
    int total = 0, close = 0;
    for (int k = 0; k < 3; ++k) {
      const ManhattanScene s = generate_manhattan_scene(rng, o);
      for (size_t i = 0; i < s.matches.lines.size(); ++i) {
        const int label = s.matches.line_vp[i];
        ASSERT_GE(label, 0);
        ++per_direction[label];
        const VpMatch& vp = s.matches.vps[label];
        // Sine of the angle between the VP direction and the segment's back-projected plane.
        const double e1 = std::abs(plane1(s, s.matches.lines[i].s1).dot(vp.d1));
        const double e2 = std::abs(plane2(s, s.matches.lines[i].s2).dot(vp.d2));
        ++total;
        if (noise == 0.0) {
          EXPECT_LT(e1, 1e-9);
          EXPECT_LT(e2, 1e-9);
        }
        if (e1 < std::sin(3.0 * kDeg) && e2 < std::sin(3.0 * kDeg)) ++close;
      }
    }
    EXPECT_GT(close, 0.97 * total) << "noise " << noise;
    for (int c : per_direction) EXPECT_GT(c, 0.1 * total);
  }
}

TEST(ManhattanScene, VanishingPointsFollowTheRotation) {
  std::mt19937_64 rng(12);
  ManhattanSceneOptions o = noiseless();
  o.num_points = 10;
  o.num_segments = 10;
  int flipped1 = 0, flipped2 = 0, total = 0;
  for (bool orient : {false, true}) {
    o.orient_vps = orient;
    for (int k = 0; k < 20; ++k) {
      const ManhattanScene s = generate_manhattan_scene(rng, o);
      ASSERT_EQ(s.matches.vps.size(), 3u);
      for (int v = 0; v < 3; ++v) {
        const VpMatch& vp = s.matches.vps[v];
        EXPECT_EQ(vp.sign_known, orient);
        EXPECT_NEAR(vp.d1.norm(), 1.0, 1e-12);
        EXPECT_NEAR(vp.d2.norm(), 1.0, 1e-12);
        EXPECT_LT(sin_angle(vp.d1, s.directions.col(v)), 1e-12);
        const Eigen::Vector3d Rd1 = s.truth.R * vp.d1;
        if (orient) {
          EXPECT_LT((vp.d2 - Rd1).norm(), 1e-12);
        } else {
          EXPECT_LT(std::min((vp.d2 - Rd1).norm(), (vp.d2 + Rd1).norm()), 1e-12);
          ++total;
          flipped1 += vp.d1.dot(s.directions.col(v)) < 0.0;
          flipped2 += vp.d2.dot(Rd1) < 0.0;
        }
      }
    }
  }
  EXPECT_GT(flipped1, 0.25 * total);
  EXPECT_LT(flipped1, 0.75 * total);
  EXPECT_GT(flipped2, 0.25 * total);
  EXPECT_LT(flipped2, 0.75 * total);
}

TEST(ManhattanScene, VanishingPointNoiseHasTheRequestedAngle) {
  std::mt19937_64 rng(13);
  ManhattanSceneOptions o = noiseless();
  o.vp_noise_deg = 2.0;
  o.orient_vps = true;
  for (int k = 0; k < 10; ++k) {
    const ManhattanScene s = generate_manhattan_scene(rng, o);
    for (int v = 0; v < 3; ++v) {
      const VpMatch& vp = s.matches.vps[v];
      const Eigen::Vector3d d = s.directions.col(v);
      EXPECT_NEAR(std::acos(std::clamp(vp.d1.dot(d), -1.0, 1.0)), 2.0 * kDeg, 1e-9);
      EXPECT_NEAR(std::acos(std::clamp(vp.d2.dot(s.truth.R * d), -1.0, 1.0)), 2.0 * kDeg, 1e-9);
    }
  }
}

TEST(ManhattanScene, VanishingPointsFittedFromSegments) {
  std::mt19937_64 rng(14);
  for (double noise : {0.0, 1.0}) {
    ManhattanSceneOptions o;
    o.noise_px = noise;
    o.lines_per_vp_fit = 8;
    o.orient_vps = true;
    for (int k = 0; k < 5; ++k) {
      const ManhattanScene s = generate_manhattan_scene(rng, o);
      for (int v = 0; v < 3; ++v) {
        const VpMatch& vp = s.matches.vps[v];
        const double e1 = std::asin(std::min(1.0, sin_angle(vp.d1, s.directions.col(v))));
        const double e2 =
            std::asin(std::min(1.0, sin_angle(vp.d2, s.truth.R * s.directions.col(v))));
        EXPECT_GT(vp.d2.dot(s.truth.R * vp.d1), 0.0);
        if (noise == 0.0) {
          EXPECT_LT(e1, 1e-9);
          EXPECT_LT(e2, 1e-9);
        } else {
          EXPECT_GT(e1 + e2, 1e-6);  // really fitted to noisy segments
          EXPECT_LT(e1, 5.0 * kDeg);
          EXPECT_LT(e2, 5.0 * kDeg);
        }
      }
    }
  }
}

TEST(ManhattanScene, OnlyProvidedVanishingPointsLabelSegments) {
  std::mt19937_64 rng(15);
  ManhattanSceneOptions o;
  o.num_vps = 1;
  o.line_outlier_ratio = 0.3;
  const ManhattanScene s = generate_manhattan_scene(rng, o);
  ASSERT_EQ(s.matches.vps.size(), 1u);
  int labelled = 0;
  for (size_t i = 0; i < s.matches.lines.size(); ++i) {
    EXPECT_EQ(s.matches.line_vp[i], s.line_direction[i] == 0 ? 0 : -1);
    labelled += s.matches.line_vp[i] == 0;
  }
  EXPECT_GT(labelled, 0);
  EXPECT_LT(labelled, static_cast<int>(s.matches.lines.size()));
}

TEST(ManhattanScene, JunctionsLieOnBothSegmentsInBothImages) {
  std::mt19937_64 rng(16);
  ManhattanSceneOptions o = noiseless();
  o.junction_fraction = 0.4;
  o.line_outlier_ratio = 0.2;
  const ManhattanScene s = generate_manhattan_scene(rng, o);
  const int inliers = std::count(s.line_inlier.begin(), s.line_inlier.end(), true);
  EXPECT_EQ(static_cast<int>(s.junctions.size()), rounded(0.4 * inliers / 2.0));
  int types[3] = {0, 0, 0};
  for (const ManhattanJunction& j : s.junctions) {
    ++types[static_cast<int>(j.type)];
    const LineMatch &a = s.matches.lines[j.segments[0]], &b = s.matches.lines[j.segments[1]];
    EXPECT_TRUE(s.line_inlier[j.segments[0]] && s.line_inlier[j.segments[1]]);
    EXPECT_EQ(s.line_plane[j.segments[0]], s.line_plane[j.segments[1]]);
    EXPECT_NE(s.line_direction[j.segments[0]], s.line_direction[j.segments[1]]);
    EXPECT_TRUE(meet_within(a.s1, b.s1, 1e-6));
    EXPECT_TRUE(meet_within(a.s2, b.s2, 1e-6));
    Eigen::Vector2d x1, x2;
    ASSERT_TRUE(intersect_lines(a.s1.line(), b.s1.line(), &x1));
    ASSERT_TRUE(intersect_lines(a.s2.line(), b.s2.line(), &x2));
    EXPECT_LT((x1 - project(s.camera1, j.point)).norm(), 1e-6);
    EXPECT_LT((x2 - project(s.camera2, s.truth.R * j.point + metric_t(s))).norm(), 1e-6);
    // Strictly inside a crossing segment, at an end of one that stops there.
    const bool crosses_a = j.type != JunctionType::kL, crosses_b = j.type == JunctionType::kX;
    auto at_end = [&](const LineSegment& seg) {
      return std::min((seg.p1 - x1).norm(), (seg.p2 - x1).norm()) < 1e-6;
    };
    EXPECT_EQ(at_end(a.s1), !crosses_a);
    EXPECT_EQ(at_end(b.s1), !crosses_b);
  }
  for (int t : types) EXPECT_GT(t, 0);
  // Random segments meet by chance too, so at least the generated junctions are found.
  EXPECT_GE(count_junctions(s, 1e-6), static_cast<int>(s.junctions.size()));

  // With noise the junctions stay within a few pixels of both segments, except for some L and T
  // junctions at acute angles, where the intersection slides along the segments.
  ManhattanSceneOptions noisy = o;
  noisy.noise_px = 0.5;
  const ManhattanScene n = generate_manhattan_scene(rng, noisy);
  int found = 0;
  for (const ManhattanJunction& j : n.junctions) {
    const LineMatch &a = n.matches.lines[j.segments[0]], &b = n.matches.lines[j.segments[1]];
    found += meet_within(a.s1, b.s1, 3.0) && meet_within(a.s2, b.s2, 3.0);
  }
  EXPECT_GE(found, 0.85 * n.junctions.size());
  EXPECT_GT(n.junctions.size(), 10u);
}

TEST(ManhattanScene, NoJunctionsWhenNotAskedFor) {
  std::mt19937_64 rng(17);
  ManhattanSceneOptions o;
  o.junction_fraction = 0.0;
  EXPECT_TRUE(generate_manhattan_scene(rng, o).junctions.empty());
  o.junction_fraction = 1.0;
  o.num_segments = 31;
  EXPECT_EQ(generate_manhattan_scene(rng, o).junctions.size(), 15u);
}

TEST(ManhattanScene, RotationAngleAndBaselineFollowTheOptions) {
  std::mt19937_64 rng(18);
  ManhattanSceneOptions o;
  o.num_points = 5;
  o.num_segments = 5;
  o.max_rotation_deg = 25.0;
  o.baseline = 0.8;
  std::vector<double> angles;
  for (int k = 0; k < 300; ++k) {
    const ManhattanScene s = generate_manhattan_scene(rng, o);
    const double angle = rotation_error(Eigen::Matrix3d::Identity(), s.truth.R) / kDeg;
    EXPECT_LE(angle, o.max_rotation_deg + 1e-9);
    angles.push_back(angle);
    EXPECT_NEAR(s.baseline_m, o.baseline, 1e-12);
    EXPECT_NEAR(s.truth.t.norm(), 1.0, 1e-12);
    EXPECT_LT((s.truth.R.transpose() * s.truth.R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    // Camera 2 moves into the half-space in front of camera 1.
    EXPECT_GE(s.truth.centre2().z(), 0.25 - 1e-12);
  }
  const double mean = std::accumulate(angles.begin(), angles.end(), 0.0) / angles.size();
  EXPECT_NEAR(mean, 0.5 * o.max_rotation_deg, 0.1 * o.max_rotation_deg);
  EXPECT_GT(*std::max_element(angles.begin(), angles.end()), 0.9 * o.max_rotation_deg);
  EXPECT_LT(*std::min_element(angles.begin(), angles.end()), 0.1 * o.max_rotation_deg);

  o.max_rotation_deg = 0.0;
  o.baseline = 0.0;
  const ManhattanScene still = generate_manhattan_scene(rng, o);
  EXPECT_LT(rotation_error(Eigen::Matrix3d::Identity(), still.truth.R), 1e-15);
  EXPECT_EQ(still.baseline_m, 0.0);
  EXPECT_EQ(still.truth.t.norm(), 0.0);
}

void expect_same(const ManhattanScene& a, const ManhattanScene& b) {
  EXPECT_EQ(a.truth.R, b.truth.R);
  EXPECT_EQ(a.truth.t, b.truth.t);
  EXPECT_EQ(a.directions, b.directions);
  ASSERT_EQ(a.matches.points.size(), b.matches.points.size());
  for (size_t i = 0; i < a.matches.points.size(); ++i) {
    EXPECT_EQ(a.matches.points[i].x1, b.matches.points[i].x1);
    EXPECT_EQ(a.matches.points[i].x2, b.matches.points[i].x2);
    EXPECT_EQ(a.points3d[i], b.points3d[i]);
  }
  ASSERT_EQ(a.matches.lines.size(), b.matches.lines.size());
  for (size_t i = 0; i < a.matches.lines.size(); ++i) {
    EXPECT_EQ(a.matches.lines[i].s1.p1, b.matches.lines[i].s1.p1);
    EXPECT_EQ(a.matches.lines[i].s2.p2, b.matches.lines[i].s2.p2);
  }
  ASSERT_EQ(a.matches.vps.size(), b.matches.vps.size());
  for (size_t i = 0; i < a.matches.vps.size(); ++i)
    EXPECT_EQ(a.matches.vps[i].d2, b.matches.vps[i].d2);
  EXPECT_EQ(a.point_inlier, b.point_inlier);
  EXPECT_EQ(a.line_inlier, b.line_inlier);
  EXPECT_EQ(a.point_plane, b.point_plane);
  EXPECT_EQ(a.line_direction, b.line_direction);
  EXPECT_EQ(a.matches.line_vp, b.matches.line_vp);
  ASSERT_EQ(a.junctions.size(), b.junctions.size());
  for (size_t i = 0; i < a.junctions.size(); ++i)
    EXPECT_EQ(a.junctions[i].segments, b.junctions[i].segments);
}

TEST(ManhattanScene, SameSeedSameScene) {
  ManhattanSceneOptions o;
  o.point_outlier_ratio = 0.2;
  o.line_outlier_ratio = 0.2;
  o.vp_noise_deg = 1.0;
  std::mt19937_64 rng_a(19), rng_b(19), rng_c(20);
  for (int k = 0; k < 3; ++k) {
    const ManhattanScene a = generate_manhattan_scene(rng_a, o);
    const ManhattanScene b = generate_manhattan_scene(rng_b, o);
    expect_same(a, b);
    const ManhattanScene c = generate_manhattan_scene(rng_c, o);
    EXPECT_NE(a.truth.R, c.truth.R);
    EXPECT_NE(a.matches.points[0].x1, c.matches.points[0].x1);
  }
}

TEST(ManhattanScene, InvalidOptionsThrow) {
  std::mt19937_64 rng(21);
  auto bad = [](auto change) {
    ManhattanSceneOptions o;
    change(o);
    return o;
  };
  using O = ManhattanSceneOptions;
  for (const O& o :
       {bad([](O& o) { o.num_points = -1; }), bad([](O& o) { o.num_vps = 4; }),
        bad([](O& o) { o.point_outlier_ratio = 1.5; }),
        bad([](O& o) { o.junction_fraction = -0.1; }), bad([](O& o) { o.noise_px = -1.0; }),
        bad([](O& o) { o.focal_px = 0.0; }), bad([](O& o) { o.min_segment_px = 500.0; }),
        bad([](O& o) { o.baseline = -1.0; })})
    EXPECT_THROW(generate_manhattan_scene(rng, o), std::invalid_argument);
  // Feasible-looking options that no scene satisfies end with an error, not an endless loop.
  EXPECT_THROW(generate_manhattan_scene(rng, bad([](O& o) { o.baseline = 50.0; })),
               std::runtime_error);
  EXPECT_THROW(generate_manhattan_scene(
                   rng, bad([](O& o) { o.min_segment_px = o.max_segment_px = 2000.0; })),
               std::runtime_error);
}

}  // namespace
}  // namespace hybrid_vo
