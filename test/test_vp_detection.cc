// Joint VP detection and matching (paper Sec. 3), the per-image baseline, and bad input.
#include <chrono>
#include <cmath>
#include <future>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/lines/vp_detection.h"
#include "hybrid_vo/synthetic/manhattan_scene.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

double axis_angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) / kDeg;
}

// The pairs: three orthogonal directions, plus clutter segments (random in each image)
// and wrong matches.
struct Pair {
  ManhattanScene scene;
  std::vector<int> truth;  // per line: Manhattan direction, or -1 for wrong matches and clutter
};

Pair make_pair(std::mt19937_64& rng, double noise_px = 0.5, int clutter = 30) {
  ManhattanSceneOptions o;
  o.num_points = 10;
  o.num_segments = 250;  // a typical LSD count; ~65 correct segments per direction
  o.noise_px = noise_px;
  o.line_outlier_ratio = 0.2;
  Pair p{generate_manhattan_scene(rng, o), {}};
  for (size_t i = 0; i < p.scene.matches.lines.size(); ++i)
    p.truth.push_back(p.scene.line_inlier[i] ? p.scene.line_direction[i] : -1);
  std::uniform_real_distribution<double> x(0.0, 799.0), y(0.0, 599.0);
  for (int i = 0; i < clutter; ++i) {
    LineMatch m;
    m.s1 = LineSegment({x(rng), y(rng)}, {x(rng), y(rng)});
    m.s2 = LineSegment({x(rng), y(rng)}, {x(rng), y(rng)});
    if (m.s1.length() < 30 || m.s2.length() < 30) continue;
    p.scene.matches.lines.push_back(m);
    p.truth.push_back(-1);
  }
  return p;
}

// Index of the Manhattan direction a VP match stands for (by its image-1 direction).
int direction_of(const ManhattanScene& s, const VpMatch& vp) {
  int best = -1;
  double best_angle = 5.0;
  for (int k = 0; k < 3; ++k) {
    const double a = axis_angle_deg(vp.d1, s.directions.col(k));
    if (a < best_angle) best_angle = a, best = k;
  }
  return best;
}

TEST(JointVpDetection, FindsTheThreeDirectionsAccuratelyWithCorrectLabels) {
  std::mt19937_64 rng(1);
  int correct = 0, labelled = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Pair p = make_pair(rng);
    const ManhattanScene& s = p.scene;
    const MatchedVps vps =
        detect_vanishing_points_joint(s.camera1, s.camera2, s.matches.lines);
    ASSERT_EQ(vps.labels.size(), s.matches.lines.size());
    std::vector<int> found(3, 0);
    std::vector<int> vp_direction;
    for (const VpMatch& m : vps.matches) {
      const int k = direction_of(s, m);
      vp_direction.push_back(k);
      if (k < 0) continue;
      found[k]++;
      EXPECT_LT(axis_angle_deg(m.d1, s.directions.col(k)), 0.5);
      EXPECT_LT(axis_angle_deg(m.d2, s.truth.R * s.directions.col(k)), 0.5);
    }
    EXPECT_EQ(found, std::vector<int>({1, 1, 1})) << "trial " << trial;
    // Labels of correct matches name their direction's VP; clutter stays unlabelled.
    for (size_t i = 0; i < p.truth.size(); ++i) {
      const bool wrong_match = i < s.line_inlier.size() && !s.line_inlier[i];
      if (wrong_match) continue;  // may legitimately join a VP when both segments share it
      ++labelled;
      const int label = vps.labels[i];
      const int direction = label >= 0 ? vp_direction[label] : -1;
      correct += direction == p.truth[i];
    }
  }
  EXPECT_GE(correct, 0.95 * labelled);
}

TEST(JointVpDetection, SignIsKnownWhenMatchedSegmentsKeepTheirOrientation) {
  std::mt19937_64 rng(2);
  const Pair p = make_pair(rng, 0.5, 0);
  const ManhattanScene& s = p.scene;
  const MatchedVps vps = detect_vanishing_points_joint(s.camera1, s.camera2, s.matches.lines);
  ASSERT_GE(vps.matches.size(), 3u);
  for (const VpMatch& m : vps.matches) {
    EXPECT_TRUE(m.sign_known);
    EXPECT_GT(m.d2.dot(s.truth.R * m.d1), 0.99);  // d2 = +R d1
  }
  // Flipping the endpoints of half the image-2 segments makes the sign unknowable.
  TwoViewMatches flipped = s.matches;
  for (size_t i = 0; i < flipped.lines.size(); i += 2)
    std::swap(flipped.lines[i].s2.p1, flipped.lines[i].s2.p2);
  const MatchedVps unknown = detect_vanishing_points_joint(s.camera1, s.camera2, flipped.lines);
  for (const VpMatch& m : unknown.matches) EXPECT_FALSE(m.sign_known);
}

TEST(JointVpDetection, RefinementImprovesTheDirections) {
  std::mt19937_64 rng(3);
  double refined = 0.0, raw = 0.0;
  VpDetectionOptions no_refine;
  no_refine.refine = false;
  for (int trial = 0; trial < 20; ++trial) {
    const Pair p = make_pair(rng, 1.0);
    const ManhattanScene& s = p.scene;
    for (const bool refine : {true, false}) {
      const MatchedVps vps = detect_vanishing_points_joint(
          s.camera1, s.camera2, s.matches.lines, refine ? VpDetectionOptions() : no_refine);
      for (const VpMatch& m : vps.matches) {
        const int k = direction_of(s, m);
        if (k < 0) continue;
        (refine ? refined : raw) += axis_angle_deg(m.d1, s.directions.col(k)) +
                                    axis_angle_deg(m.d2, s.truth.R * s.directions.col(k));
      }
    }
  }
  EXPECT_LT(refined, raw);
}

TEST(StandardVpDetection, PerImageDetectionThenMatching) {
  std::mt19937_64 rng(4);
  const Pair p = make_pair(rng);
  const ManhattanScene& s = p.scene;
  const MatchedVps vps = detect_vanishing_points_standard(s.camera1, s.camera2, s.matches.lines);
  std::vector<int> found(3, 0);
  for (const VpMatch& m : vps.matches) {
    const int k = direction_of(s, m);
    if (k < 0) continue;
    found[k]++;
    EXPECT_LT(axis_angle_deg(m.d2, s.truth.R * s.directions.col(k)), 1.0);
  }
  EXPECT_EQ(found, std::vector<int>({1, 1, 1}));
}

TEST(SingleImageVpDetection, FindsTheThreeDirections) {
  std::mt19937_64 rng(5);
  const Pair p = make_pair(rng);
  std::vector<LineSegment> segments;
  for (const LineMatch& m : p.scene.matches.lines) segments.push_back(m.s1);
  const SingleImageVps vps = detect_vanishing_points(p.scene.camera1, segments);
  ASSERT_GE(vps.vps.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    double best = 90.0;
    for (const ImageVp& vp : vps.vps)
      best = std::min(best, axis_angle_deg(vp.direction, p.scene.directions.col(k)));
    EXPECT_LT(best, 0.5) << "direction " << k;
  }
  for (size_t v = 0; v + 1 < vps.vps.size(); ++v) EXPECT_GE(vps.vps[v].score, vps.vps[v + 1].score);
}

TEST(JointVpDetection, ManhattanPriorDropsAnObliqueDirection) {
  std::mt19937_64 rng(6);
  Pair p = make_pair(rng, 0.3, 0);
  ManhattanScene& s = p.scene;
  // A fourth family of 3D lines at 45 degrees to two of the directions.
  const Eigen::Vector3d oblique = (s.directions.col(1) + s.directions.col(2)).normalized();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto project = [](const PinholeCamera& c, const Eigen::Vector3d& X) {
    return c.denormalize(X.head<2>() / X.z());
  };
  const Eigen::Vector3d centre2 = -s.truth.R.transpose() * (s.baseline_m * s.truth.t);
  for (int added = 0; added < 25;) {
    const Eigen::Vector3d A(3.0 * u(rng), 1.5 * u(rng), 8.0 + 2.0 * u(rng));
    const Eigen::Vector3d B = A + 1.5 * oblique;
    LineMatch m;
    m.s1 = LineSegment(project(s.camera1, A), project(s.camera1, B));
    m.s2 = LineSegment(project(s.camera2, s.truth.R * (A - centre2)),
                       project(s.camera2, s.truth.R * (B - centre2)));
    if (!s.camera1.in_image(m.s1.p1) || !s.camera1.in_image(m.s1.p2) ||
        !s.camera2.in_image(m.s2.p1) || !s.camera2.in_image(m.s2.p2) || m.s1.length() < 40)
      continue;
    s.matches.lines.push_back(m);
    ++added;
  }
  auto count_oblique = [&](const MatchedVps& vps) {
    int n = 0;
    for (const VpMatch& m : vps.matches) n += axis_angle_deg(m.d1, oblique) < 2.0;
    return n;
  };
  EXPECT_EQ(count_oblique(detect_vanishing_points_joint(s.camera1, s.camera2, s.matches.lines)), 1);
  VpDetectionOptions manhattan;
  manhattan.manhattan = true;
  const MatchedVps prior =
      detect_vanishing_points_joint(s.camera1, s.camera2, s.matches.lines, manhattan);
  EXPECT_EQ(count_oblique(prior), 0);
  EXPECT_GE(prior.matches.size(), 2u);
}

// Issue 30: a white room has a handful of long edges. Three long segments of one direction are a
// VP when long-segment evidence is on (three segments of 150 px per image), three short ones are
// not, and with the count rule alone (6) neither is.
TEST(JointVpDetection, AVpFromThreeLongSegments) {
  const PinholeCamera camera(500, 500, 320, 240, 640, 480);
  const Eigen::Matrix3d R = rotation_about(Eigen::Vector3d(0.2, 1.0, 0.1), 3.0 * kDeg);
  const Eigen::Vector3d t(0.05, 0.0, 0.01);
  const Eigen::Vector3d vertical = Eigen::Vector3d(0.05, 1.0, 0.2).normalized();
  const Eigen::Vector3d across = vertical.cross(Eigen::Vector3d::UnitZ()).normalized();
  auto project = [&](const Eigen::Vector3d& X, bool second) {
    const Eigen::Vector3d Y = second ? Eigen::Vector3d(R * X + t) : X;
    return Eigen::Vector2d(camera.fx * Y.x() / Y.z() + camera.cx,
                           camera.fy * Y.y() / Y.z() + camera.cy);
  };
  auto segments_along = [&](const Eigen::Vector3d& d, const std::vector<Eigen::Vector3d>& starts,
                            double length, std::vector<LineMatch>* out) {
    for (const Eigen::Vector3d& X : starts)
      out->push_back({LineSegment(project(X, false), project(X + length * d, false)),
                      LineSegment(project(X, true), project(X + length * d, true))});
  };
  const std::vector<Eigen::Vector3d> starts = {
      {-1.0, -0.8, 3.0}, {0.2, -0.7, 3.5}, {1.1, -0.9, 3.2}};
  std::vector<LineMatch> long_lines, short_lines;
  segments_along(vertical, starts, 1.6, &long_lines);   // ~230 px each
  segments_along(vertical, starts, 0.25, &short_lines);  // ~35 px each
  // Two segments across, so that the pencil is not the only direction.
  for (auto* lines : {&long_lines, &short_lines})
    segments_along(across, {{-1.2, 0.6, 3.0}, {-0.8, 0.9, 3.4}}, 0.8, lines);
  VpDetectionOptions options;
  options.min_inliers = 6;
  EXPECT_TRUE(detect_vanishing_points_joint(camera, camera, long_lines, options).matches.empty());
  options.min_long_inliers = 3;
  options.min_support_px = 150.0;
  const MatchedVps found = detect_vanishing_points_joint(camera, camera, long_lines, options);
  ASSERT_EQ(found.matches.size(), 1u);
  EXPECT_LT(axis_angle_deg(found.matches[0].d1, vertical), 0.05);
  EXPECT_LT(axis_angle_deg(found.matches[0].d2, R * vertical), 0.05);
  EXPECT_EQ(found.inliers[0], (std::vector<int>{0, 1, 2}));
  EXPECT_TRUE(detect_vanishing_points_joint(camera, camera, short_lines, options).matches.empty());
}

// Whether f() returns within `seconds`. A detector that loops forever fails the test instead of
// stalling the suite (the thread is left to the process's exit).
template <class F>
bool returns_within(double seconds, F f) {
  auto done = std::make_shared<std::promise<void>>();
  std::future<void> finished = done->get_future();
  std::thread([done, f]() mutable {
    f();
    done->set_value();
  }).detach();
  return finished.wait_for(std::chrono::duration<double>(seconds)) == std::future_status::ready;
}

// Three short, nearly parallel segments (of a JPEG-compressed render, seed 6, where the node once
// stopped answering): the VP of any two takes all three, but their length-weighted refit lies 3 to
// 6 px off each. Left over after the verticals' VP, they must not be drawn again forever.
TEST(VpDetectionBadInput, ALoosePencilNoRefitHoldsEnds) {
  const PinholeCamera camera(460.8, 460.8, 319.5, 239.5, 640, 480);
  std::vector<LineMatch> lines = {
      {LineSegment({273.0360107421875, 265.73431396484375}, {309.90093994140625, 270.7308349609375}),
       LineSegment({271.92532348632812, 266.57818603515625}, {311.90426635742188, 271.74130249023438})},
      {LineSegment({307.90673828125, 277.73757934570312}, {271.97537231445312, 273.19491577148438}),
       LineSegment({312.11611938476562, 279.050048828125}, {272.96768188476562, 274.26449584960938})},
      {LineSegment({328.92233276367188, 274.7586669921875}, {281.014892578125, 269.85446166992188}),
       LineSegment({314.09405517578125, 274.06637573242188}, {277.9571533203125, 270.42529296875})}};
  for (const double x : {40, 90, 140, 190, 440, 490, 540, 590})
    lines.push_back({LineSegment({x, 300}, {x, 450}), LineSegment({x, 300}, {x, 450})});
  VpDetectionOptions options;  // as the front end's
  options.min_long_inliers = 3;
  options.min_support_px = 150.0;
  auto found = std::make_shared<MatchedVps>();
  ASSERT_TRUE(returns_within(20.0, [=] {
    *found = detect_vanishing_points_joint(camera, camera, lines, options);
  })) << "the detector did not return";
  ASSERT_EQ(found->matches.size(), 1u);
  EXPECT_LT(axis_angle_deg(found->matches[0].d1, Eigen::Vector3d::UnitY()), 0.01);
  EXPECT_EQ(found->labels, (std::vector<int>{-1, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0}));
}

// The case above in random forms: a loose pencil of four short segments a few degrees apart,
// beside the verticals' VP. About one in 40 such pencils made the old detector loop forever (one
// in 300 of three segments); every detector must return, with labels and directions that agree,
// and find the verticals.
TEST(VpDetectionBadInput, RandomLoosePencilsAlwaysReturn) {
  const PinholeCamera camera(460.8, 460.8, 319.5, 239.5, 640, 480);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::vector<std::vector<LineMatch>> instances(600);
  for (std::vector<LineMatch>& lines : instances) {
    const double angle = (u(rng) - 0.5) * 120.0 * kDeg;  // at least 30 degrees off the verticals
    const Eigen::Vector2d centre(150 + 340 * u(rng), 100 + 280 * u(rng));
    for (int i = 0; i < 4; ++i) {
      const double a = angle + (u(rng) - 0.5) * 4.0 * kDeg, half = 0.5 * (35 + 15 * u(rng));
      const Eigen::Vector2d c = centre + Eigen::Vector2d(50 * u(rng), 15 * u(rng));
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      const LineSegment s(c - half * d, c + half * d);
      lines.push_back({s, LineSegment(s.p1 + Eigen::Vector2d(noise(rng), noise(rng)),
                                      s.p2 + Eigen::Vector2d(noise(rng), noise(rng)))});
    }
    for (const double x : {40, 90, 140, 190, 440, 490, 540, 590})
      lines.push_back({LineSegment({x, 300}, {x, 450}), LineSegment({x, 300}, {x, 450})});
  }
  VpDetectionOptions options;  // as the front end's
  options.min_long_inliers = 3;
  options.min_support_px = 150.0;
  auto results = std::make_shared<std::vector<MatchedVps>>();
  auto singles = std::make_shared<std::vector<SingleImageVps>>();
  ASSERT_TRUE(returns_within(30.0, [=] {
    for (const std::vector<LineMatch>& lines : instances) {
      results->push_back(detect_vanishing_points_joint(camera, camera, lines, options));
      std::vector<LineSegment> first;
      for (const LineMatch& m : lines) first.push_back(m.s1);
      singles->push_back(detect_vanishing_points(camera, first, options));
    }
  })) << "a detector did not return";
  int found = 0;
  for (size_t k = 0; k < instances.size(); ++k) {
    const MatchedVps& r = (*results)[k];
    ASSERT_EQ(r.labels.size(), instances[k].size());
    ASSERT_EQ(r.inliers.size(), r.matches.size());
    for (size_t v = 0; v < r.matches.size(); ++v) {
      for (const Eigen::Vector3d& d : {r.matches[v].d1, r.matches[v].d2})
        EXPECT_TRUE(d.allFinite() && d.norm() > 0.0);
      for (const int i : r.inliers[v]) EXPECT_EQ(r.labels[i], static_cast<int>(v));
    }
    for (const int label : r.labels) EXPECT_LT(label, static_cast<int>(r.matches.size()));
    EXPECT_EQ((*singles)[k].labels.size(), instances[k].size());
    for (const VpMatch& m : r.matches)
      found += axis_angle_deg(m.d1, Eigen::Vector3d::UnitY()) < 0.5;
  }
  EXPECT_EQ(found, static_cast<int>(instances.size()));
}

TEST(VpDetectionBadInput, FewParallelOrNanSegmentsGiveNothing) {
  const PinholeCamera camera(600, 600, 400, 300, 800, 600);
  std::vector<LineMatch> few = {
      {LineSegment({10, 10}, {200, 40}), LineSegment({12, 10}, {202, 40})},
      {LineSegment({10, 300}, {300, 320}), LineSegment({12, 300}, {302, 320})},
      {LineSegment({500, 10}, {520, 400}), LineSegment({502, 10}, {522, 400})}};
  EXPECT_TRUE(detect_vanishing_points_joint(camera, camera, few).matches.empty());

  std::vector<LineMatch> parallel;
  for (int i = 0; i < 40; ++i)
    parallel.push_back({LineSegment({10.0 + 15 * i, 50}, {10.0 + 15 * i, 400}),
                        LineSegment({14.0 + 15 * i, 60}, {14.0 + 15 * i, 410})});
  MatchedVps result = detect_vanishing_points_joint(camera, camera, parallel);
  EXPECT_TRUE(result.matches.empty());
  EXPECT_EQ(result.labels, std::vector<int>(parallel.size(), -1));

  std::vector<LineMatch> nan = parallel;
  for (LineMatch& m : nan) m.s1.p1.x() = NAN;
  EXPECT_TRUE(detect_vanishing_points_joint(camera, camera, nan).matches.empty());
  std::vector<LineSegment> nan_single;
  for (const LineMatch& m : nan) nan_single.push_back(m.s1);
  EXPECT_TRUE(detect_vanishing_points(camera, nan_single).vps.empty());
  EXPECT_TRUE(detect_vanishing_points_standard(camera, camera, nan).matches.empty());

  PinholeCamera broken = camera;
  broken.fy = 0.0;
  std::mt19937_64 rng(7);
  const Pair p = make_pair(rng);
  EXPECT_TRUE(detect_vanishing_points_joint(broken, camera, p.scene.matches.lines).matches.empty());
  EXPECT_TRUE(detect_vanishing_points_joint(camera, camera, {}).matches.empty());
}

}  // namespace
}  // namespace hybrid_vo

#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/lines/two_view.h"

namespace hybrid_vo {
namespace {

// Without given VPs the two-view estimator detects them jointly and the VP solvers use them.
TEST(TwoView, DetectsVpsWhenNoneAreGiven) {
  std::mt19937_64 rng(8);
  ManhattanSceneOptions o;
  o.num_points = 30;
  o.point_outlier_ratio = 0.5;
  o.num_segments = 200;
  o.line_outlier_ratio = 0.2;
  o.num_vps = 0;  // nothing given
  const ManhattanScene s = generate_manhattan_scene(rng, o);
  ASSERT_TRUE(s.matches.vps.empty());
  const TwoViewEstimate result = estimate_two_view(s.camera1, s.camera2, s.matches);
  EXPECT_TRUE(result.vps_detected);
  EXPECT_EQ(result.vps.matches.size(), 3u);
  ASSERT_EQ(result.estimate.status, EstimationStatus::kOk);
  EXPECT_EQ(result.estimate.num_vp_inliers, 3);
  EXPECT_LT(rotation_error(result.estimate.pose.R, s.truth.R) * 180.0 / M_PI, 0.3);
  // A point-only preset never detects.
  TwoViewOptions points_only;
  preset_options("5pc", &points_only);
  EXPECT_FALSE(estimate_two_view(s.camera1, s.camera2, s.matches, points_only).vps_detected);
}

}  // namespace
}  // namespace hybrid_vo
