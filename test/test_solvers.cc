// Random-instance tests of the thirteen minimal solvers (issue: noiseless, noisy).
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hybrid_vo/estimation/refine_relative_pose.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/solvers/minimal_solver.h"
#include "hybrid_vo/solvers/relpose_homography.h"
#include "hybrid_vo/synthetic/minimal_instances.h"
#include "solver_test_utils.h"

namespace hybrid_vo {
namespace {

using testing::all_valid;
using testing::best_error;
using testing::median;

constexpr int kNoiselessInstances = 1000;
constexpr double kNoiselessTolerance = 1e-6;  // rad, rotation and translation
constexpr double kRequiredSuccess = 0.995;

class MinimalSolverTest : public ::testing::TestWithParam<SolverId> {
 protected:
  const SolverInfo& info() const { return solver_info(GetParam()); }

  // Fraction of instances whose truth is among the solutions, to kNoiselessTolerance.
  double noiseless_success(const MinimalInstanceOptions& options, uint64_t seed) {
    std::mt19937_64 rng(seed);
    RelativePoses poses;
    int successes = 0;
    for (int i = 0; i < kNoiselessInstances; ++i) {
      const MinimalInstance instance = generate_minimal_instance(GetParam(), rng, options);
      const int n = solve_minimal(GetParam(), instance.sample, &poses);
      EXPECT_EQ(n, static_cast<int>(poses.size()));
      EXPECT_TRUE(all_valid(poses)) << info().code << " instance " << i;
      const auto e = best_error(poses, instance.truth);
      if (e.rotation < kNoiselessTolerance && e.translation < kNoiselessTolerance) ++successes;
    }
    return static_cast<double>(successes) / kNoiselessInstances;
  }
};

TEST_P(MinimalSolverTest, NoiselessTruthIsAmongSolutions) {
  EXPECT_GE(noiseless_success({}, 100 + static_cast<int>(GetParam())), kRequiredSuccess)
      << info().code;
}

using VpSolverTest = MinimalSolverTest;

TEST_P(VpSolverTest, NoiselessWithKnownVpSigns) {
  MinimalInstanceOptions options;
  options.orient_vps = true;
  EXPECT_GE(noiseless_success(options, 200 + static_cast<int>(GetParam())), kRequiredSuccess)
      << info().code;
}

TEST_P(VpSolverTest, KnownVpSignsNeedFewerSolutions) {
  std::mt19937_64 rng(300);
  RelativePoses poses;
  long with_sign = 0, without_sign = 0;
  for (int i = 0; i < 200; ++i) {
    MinimalInstanceOptions options;
    options.orient_vps = true;
    MinimalInstance instance = generate_minimal_instance(GetParam(), rng, options);
    with_sign += solve_minimal(GetParam(), instance.sample, &poses);
    instance.sample.vp_signs_known = false;
    without_sign += solve_minimal(GetParam(), instance.sample, &poses);
  }
  EXPECT_LT(with_sign, without_sign);
}

// Paper supp. Fig. 5 protocol: 1 px noise at f = 1000 on every point and endpoint, VPs from three
// noisy segments each, and each solution locally optimised on 50 further noisy points (plus the
// sample's points and VPs); the refined solution with the lowest cost is kept. A VP from three
// 1 px segments is good to about 1 degree, twenty times worse than a point's 1e-3, hence its weight.
TEST_P(MinimalSolverTest, NoisyWithLocalOptimisationMedianBelowOneDegree) {
  MinimalInstanceOptions options;
  options.noise = 1.0 / 1000.0;
  options.lines_per_vp = 3;
  options.extra_points = 50;
  std::mt19937_64 rng(400 + static_cast<int>(GetParam()));
  RelativePoses poses;
  std::vector<double> errors;
  for (int i = 0; i < 500; ++i) {
    const MinimalInstance instance = generate_minimal_instance(GetParam(), rng, options);
    solve_minimal(GetParam(), instance.sample, &poses);
    EXPECT_TRUE(all_valid(poses));
    std::vector<Eigen::Vector2d> x1 = instance.extra_x1, x2 = instance.extra_x2;
    for (int k = 0; k < info().num_points; ++k) {
      x1.push_back(instance.sample.x1[k]);
      x2.push_back(instance.sample.x2[k]);
    }
    const std::vector<Eigen::Vector3d> v1(instance.sample.v1.begin(),
                                          instance.sample.v1.begin() + info().num_vps);
    const std::vector<Eigen::Vector3d> v2(instance.sample.v2.begin(),
                                          instance.sample.v2.begin() + info().num_vps);
    double best_cost = INFINITY, error = M_PI;
    for (RelativePose pose : poses) {
      if (pose.t.norm() == 0.0) continue;
      RelativePoseRefinementOptions refinement;
      refinement.vp_weight = 0.05;
      const auto summary = refine_relative_pose(x1, x2, v1, v2, refinement, &pose);
      if (summary.final_cost < best_cost) {
        best_cost = summary.final_cost;
        error = pose_error(pose, instance.truth);
      }
    }
    errors.push_back(error);
  }
  const double median_deg = median(errors) * 180.0 / M_PI;
  EXPECT_LT(median_deg, 1.0) << info().code;
  RecordProperty("median_error_deg", std::to_string(median_deg));
}

// Without local optimisation the errors of a minimal solver are large at 1 px (they are plotted
// by hybrid_vo_bench_solvers --noise-curve); what must hold is that they shrink with the noise.
TEST_P(MinimalSolverTest, NoisyErrorShrinksWithTheNoise) {
  double medians[2];
  const double noise_px[2] = {1.0, 0.01};
  for (int level = 0; level < 2; ++level) {
    MinimalInstanceOptions options;
    options.noise = noise_px[level] / 1000.0;
    options.lines_per_vp = 3;
    std::mt19937_64 rng(450 + static_cast<int>(GetParam()));
    RelativePoses poses;
    std::vector<double> errors;
    for (int i = 0; i < 500; ++i) {
      const MinimalInstance instance = generate_minimal_instance(GetParam(), rng, options);
      solve_minimal(GetParam(), instance.sample, &poses);
      EXPECT_TRUE(all_valid(poses));
      errors.push_back(best_error(poses, instance.truth).pose());
    }
    medians[level] = median(errors);
  }
  // 100x less noise: at least 30x smaller median error (linear regime, no instability).
  EXPECT_LT(medians[1], medians[0] / 30.0) << info().code;
  EXPECT_LT(medians[1] * 180.0 / M_PI, 1.0) << info().code;
}

// 2-2-0 is degenerate by construction; test_solver_degenerate covers it.
INSTANTIATE_TEST_SUITE_P(WellPosed, MinimalSolverTest,
                         ::testing::ValuesIn(testing::well_posed_solvers()), testing::solver_name);
INSTANTIATE_TEST_SUITE_P(WithVanishingPoints, VpSolverTest,
                         ::testing::ValuesIn(testing::vp_solvers()), testing::solver_name);

// The homography "DLT" maps the projective frame instead of eliminating (relpose_homography.h).
// Distance between two homographies up to scale and sign.
double homography_distance(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  const Eigen::Matrix3d a = A / A.norm(), b = B / B.norm();
  return std::min((a - b).norm(), (a + b).norm());
}

Eigen::Matrix3d random_homography(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix3d H;
  do {
    for (int i = 0; i < 9; ++i) H(i) = n(rng);
    H += 2.0 * Eigen::Matrix3d::Identity();
  } while (std::abs(H.determinant()) < 0.1 * std::pow(H.norm(), 3) / 27.0);
  return H;
}

// Calls fit(c, d, skip, side) for each of the four correspondences a_k <-> b_k moved onto the line
// of two others, in image 1 (side 0) or image 2: the collinear triples a 4-point map must reject.
template <typename Vector, typename Fit>
void for_each_collinear_triple(const Vector* a, const Vector* b, Fit fit) {
  for (int skip = 0; skip < 4; ++skip) {
    for (int side = 0; side < 2; ++side) {
      Vector c[4] = {a[0], a[1], a[2], a[3]}, d[4] = {b[0], b[1], b[2], b[3]};
      Vector* v = side == 0 ? c : d;
      const int i = (skip + 1) % 4, j = (skip + 2) % 4, k = (skip + 3) % 4;
      v[k] = 0.3 * v[i] + 0.7 * v[j];
      fit(c, d, skip, side);
    }
  }
}

Eigen::Vector2d apply_homography(const Eigen::Matrix3d& H, const Eigen::Vector2d& x) {
  return (H * homogeneous(x)).hnormalized();
}

TEST(HomographyFromCorrespondences, RandomProjectiveMapsAreExact) {
  std::mt19937_64 rng(800);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> scale(0.2, 5.0);
  auto random_vector = [&] { return Eigen::Vector3d(n(rng), n(rng), n(rng)); };
  int exact4 = 0, exact_dual = 0;
  const int trials = 1000;
  for (int trial = 0; trial < trials; ++trial) {
    const Eigen::Matrix3d G = random_homography(rng);
    // Any scale and sign on either side.
    Eigen::Vector3d a[4], b[4];
    for (int i = 0; i < 4; ++i) {
      a[i] = random_vector();
      b[i] = (i % 2 ? -scale(rng) : scale(rng)) * (G * a[i]);
    }
    Eigen::Matrix3d estimate;
    ASSERT_TRUE(homography_from_4_correspondences(a, b, &estimate));
    EXPECT_NEAR(estimate.norm(), 1.0, 1e-12);
    if (homography_distance(estimate, G) < 1e-10) ++exact4;
    // Three of the kind and one dual: G^T g ~ f.
    const Eigen::Vector3d f = random_vector();
    const Eigen::Vector3d g = -scale(rng) * (G.transpose().inverse() * f);
    ASSERT_TRUE(homography_from_3_correspondences_and_dual(a, b, f, g, &estimate));
    if (homography_distance(estimate, G) < 1e-10) ++exact_dual;
  }
  // Random frames are sometimes nearly collinear, where any method loses digits.
  EXPECT_GE(exact4, 0.995 * trials);
  EXPECT_GE(exact_dual, 0.995 * trials);
}

TEST(HomographyFromCorrespondences, CollinearTriplesAndIncidencesAreRejected) {
  std::mt19937_64 rng(801);
  const Eigen::Matrix3d G = random_homography(rng);
  Eigen::Vector3d a[4] = {{0.1, 0.2, 1.0}, {-0.3, 0.1, 1.0}, {0.2, -0.4, 1.0}, {0.5, 0.4, 1.0}};
  Eigen::Vector3d b[4];
  for (int i = 0; i < 4; ++i) b[i] = G * a[i];
  Eigen::Matrix3d H;
  ASSERT_TRUE(homography_from_4_correspondences(a, b, &H));
  // Every triple, in either image.
  for_each_collinear_triple(a, b, [&](const Eigen::Vector3d* c, const Eigen::Vector3d* d, int skip,
                                      int side) {
    EXPECT_FALSE(homography_from_4_correspondences(c, d, &H)) << skip << " " << side;
  });
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  Eigen::Vector3d with_zero[4] = {a[0], zero, a[2], a[3]};
  EXPECT_FALSE(homography_from_4_correspondences(with_zero, b, &H));
  Eigen::Vector3d with_nan[4] = {a[0], a[1], a[2], Eigen::Vector3d(NAN, 0.0, 1.0)};
  EXPECT_FALSE(homography_from_4_correspondences(with_nan, b, &H));
  // Dual: an a_i on f or a b_i on g.
  const Eigen::Vector3d f = a[0].cross(a[3]), g = G.transpose().inverse() * f;
  EXPECT_FALSE(homography_from_3_correspondences_and_dual(a, b, f, g, &H));
  const Eigen::Vector3d f2(0.3, -0.2, 1.0), g2 = G.transpose().inverse() * f2;
  ASSERT_TRUE(homography_from_3_correspondences_and_dual(a, b, f2, g2, &H));
  EXPECT_LT(homography_distance(H, G), 1e-12);
  EXPECT_FALSE(homography_from_3_correspondences_and_dual(a, b, f2, zero, &H));
  Eigen::Vector3d collinear[3] = {a[0], a[1], 2.0 * a[0] - a[1]};
  EXPECT_FALSE(homography_from_3_correspondences_and_dual(collinear, b, f2, g2, &H));
}

// Every mix of points and segments (the segments' endpoints need not correspond).
TEST(HomographyFromPointsAndLines, EveryMixRecoversARandomHomography) {
  std::mt19937_64 rng(802);
  std::uniform_real_distribution<double> u(-0.6, 0.6), along(-0.5, 1.5);
  for (const int num_points : {4, 3, 1, 0}) {
    const int num_lines = 4 - num_points;
    int exact = 0;
    const int trials = 1000;
    for (int trial = 0; trial < trials; ++trial) {
      const Eigen::Matrix3d H = random_homography(rng);
      Eigen::Vector2d x1[4], x2[4];
      LineSegment s1[4], s2[4];
      for (int i = 0; i < num_points; ++i) {
        x1[i] = Eigen::Vector2d(u(rng), u(rng));
        x2[i] = apply_homography(H, x1[i]);
      }
      for (int i = 0; i < num_lines; ++i) {
        const Eigen::Vector2d p(u(rng), u(rng)), q(u(rng), u(rng));
        s1[i] = LineSegment(p, q);
        // Other points of the same line in image 2.
        const double t1 = along(rng), t2 = along(rng);
        s2[i] = LineSegment(apply_homography(H, p + t1 * (q - p)), apply_homography(H, p + t2 * (q - p)));
      }
      Eigen::Matrix3d estimate;
      if (!homography_from_points_and_lines(x1, x2, num_points, s1, s2, num_lines, &estimate))
        continue;
      EXPECT_TRUE(all_finite(estimate));
      if (homography_distance(estimate, H) < 1e-10) ++exact;
    }
    EXPECT_GE(exact, 0.995 * trials) << num_points << " points";
  }
}

TEST(HomographyFromPointsAndLines, DegenerateMixesAreRejected) {
  std::mt19937_64 rng(803);
  const Eigen::Matrix3d H = random_homography(rng);
  const Eigen::Vector2d x1[4] = {{0.1, 0.2}, {-0.3, 0.1}, {0.2, -0.4}, {0.5, 0.4}};
  Eigen::Vector2d x2[4];
  for (int i = 0; i < 4; ++i) x2[i] = apply_homography(H, x1[i]);
  const LineSegment s1[4] = {{{-0.5, 0.3}, {0.4, 0.5}}, {{-0.2, -0.5}, {0.1, 0.6}},
                             {{0.6, -0.1}, {0.3, 0.5}}, {{-0.6, -0.2}, {0.5, -0.3}}};
  LineSegment s2[4];
  for (int i = 0; i < 4; ++i)
    s2[i] = LineSegment(apply_homography(H, s1[i].p1), apply_homography(H, s1[i].p2));
  Eigen::Matrix3d estimate;
  for (const int num_points : {4, 3, 1, 0}) {
    ASSERT_TRUE(homography_from_points_and_lines(x1, x2, num_points, s1, s2, 4 - num_points,
                                                 &estimate));
    EXPECT_LT(homography_distance(estimate, H), 1e-12) << num_points << " points";
  }
  EXPECT_FALSE(homography_from_points_and_lines(x1, x2, 2, s1, s2, 2, &estimate));
  EXPECT_FALSE(homography_from_points_and_lines(x1, x2, 4, s1, s2, 1, &estimate));
  EXPECT_FALSE(homography_from_points_and_lines(x1, x2, -1, s1, s2, 5, &estimate));
  // 3-1-0 with the line through one of the points; 1-3-0 with the point on one of the lines.
  LineSegment through1(x1[1], x1[1] + Eigen::Vector2d(0.3, 0.1)),
      through2(x2[1], apply_homography(H, x1[1] + Eigen::Vector2d(0.3, 0.1)));
  EXPECT_FALSE(homography_from_points_and_lines(x1, x2, 3, &through1, &through2, 1, &estimate));
  const Eigen::Vector2d on1 = 0.25 * s1[0].p1 + 0.75 * s1[0].p2;
  const Eigen::Vector2d on2 = apply_homography(H, on1);
  EXPECT_FALSE(homography_from_points_and_lines(&on1, &on2, 1, s1, s2, 3, &estimate));
  // Zero-length segment, concurrent lines, collinear points.
  LineSegment z1[4] = {s1[0], s1[1], s1[2], LineSegment(s1[3].p1, s1[3].p1)};
  LineSegment z2[4] = {s2[0], s2[1], s2[2], LineSegment(s2[3].p1, s2[3].p1)};
  EXPECT_FALSE(homography_from_points_and_lines(x1, x2, 0, z1, z2, 4, &estimate));
  const Eigen::Vector2d centre1(0.05, -0.02), centre2 = apply_homography(H, centre1);
  LineSegment c1[4], c2[4];
  for (int i = 0; i < 4; ++i) {
    c1[i] = i < 3 ? LineSegment(centre1, s1[i].p2) : s1[i];
    c2[i] = i < 3 ? LineSegment(centre2, s2[i].p2) : s2[i];
  }
  EXPECT_FALSE(homography_from_points_and_lines(x1, x2, 0, c1, c2, 4, &estimate));
  Eigen::Vector2d y1[4] = {x1[0], x1[1], 0.4 * x1[0] + 0.6 * x1[1], x1[3]}, y2[4];
  for (int i = 0; i < 4; ++i) y2[i] = apply_homography(H, y1[i]);
  EXPECT_FALSE(homography_from_points_and_lines(y1, y2, 4, s1, s2, 0, &estimate));
  EXPECT_FALSE(homography_from_points_and_lines(y1, y2, 3, s1, s2, 1, &estimate));
}

// The written-out 4-0-0 DLT is the general projective-frame map on centred points: the same
// homography to rounding, and the same rejections (every collinear triple, either image; NaN).
TEST(Homography4pt, AgreesWithTheGeneralMapAndRejectsCollinearTriples) {
  std::mt19937_64 rng(804);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  int agree = 0;
  const int trials = 2000;
  for (int trial = 0; trial < trials; ++trial) {
    const Eigen::Matrix3d H = random_homography(rng);
    Eigen::Vector2d x1[4], x2[4];
    Eigen::Vector3d a[4], b[4];
    const Eigen::Vector2d shift(u(rng), u(rng));
    for (int i = 0; i < 4; ++i) {
      x1[i] = Eigen::Vector2d(u(rng), u(rng)) + shift;
      x2[i] = apply_homography(H, x1[i]);
      a[i] = homogeneous(x1[i]);
      b[i] = homogeneous(x2[i]);
    }
    Eigen::Matrix3d fast, general;
    const bool ok_fast = homography_4pt(x1, x2, &fast);
    ASSERT_EQ(ok_fast, homography_from_4_correspondences(a, b, &general)) << trial;
    if (!ok_fast) continue;
    EXPECT_NEAR(fast.norm(), 1.0, 1e-12);
    if (homography_distance(fast, H) < 1e-10 && homography_distance(fast, general) < 1e-10)
      ++agree;
  }
  EXPECT_GE(agree, 0.995 * trials);

  const Eigen::Matrix3d H = random_homography(rng);
  const Eigen::Vector2d x1[4] = {{0.1, 0.2}, {-0.3, 0.1}, {0.2, -0.4}, {0.5, 0.4}};
  Eigen::Vector2d x2[4];
  for (int i = 0; i < 4; ++i) x2[i] = apply_homography(H, x1[i]);
  Eigen::Matrix3d estimate;
  ASSERT_TRUE(homography_4pt(x1, x2, &estimate));
  EXPECT_LT(homography_distance(estimate, H), 1e-12);
  for_each_collinear_triple(x1, x2, [&](const Eigen::Vector2d* c, const Eigen::Vector2d* d,
                                        int skip, int side) {
    EXPECT_FALSE(homography_4pt(c, d, &estimate)) << skip << " " << side;
  });
  Eigen::Vector2d with_nan[4] = {x1[0], x1[1], Eigen::Vector2d(NAN, 0.0), x1[3]};
  EXPECT_FALSE(homography_4pt(with_nan, x2, &estimate));
  Eigen::Vector2d with_inf[4] = {x1[0], x1[1], x1[2], Eigen::Vector2d(INFINITY, 1.0)};
  EXPECT_FALSE(homography_4pt(x1, with_inf, &estimate));
}

TEST(SolverTable, ThirteenConfigurationsInPaperOrder) {
  const auto& table = solver_table();
  ASSERT_EQ(table.size(), 13u);
  const char* codes[13] = {"5-0-0", "4-0-0", "3-1-0", "2-2-0", "1-3-0", "0-4-0", "2-3-0",
                           "3-0-1", "0-3-1", "2-0-2", "2-1-1⊥", "1-2-1⊥", "2-0-1⊥"};
  for (int i = 0; i < 13; ++i) {
    EXPECT_STREQ(table[i].code, codes[i]);
    EXPECT_EQ(static_cast<int>(table[i].id), i);
    // The code is the count of points, lines and VPs.
    const std::string code = table[i].code;
    EXPECT_EQ(code[0] - '0', table[i].num_points);
    EXPECT_EQ(code[2] - '0', table[i].num_lines);
    EXPECT_EQ(code[4] - '0', table[i].num_vps);
  }
  SolverId id;
  ASSERT_TRUE(find_solver("2-1-1p", &id));
  EXPECT_EQ(id, SolverId::k1vpOrthline2pt);
  ASSERT_TRUE(find_solver("relpose_1vp_3pt", &id));
  EXPECT_EQ(id, SolverId::k1vp3pt);
  EXPECT_FALSE(find_solver("7-0-0", &id));
}

}  // namespace
}  // namespace hybrid_vo
