// Degenerate and invalid input for every minimal solver: 0 solutions or valid ones, never NaN.
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "hybrid_vo/geometry/homography.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/solvers/minimal_solver.h"
#include "hybrid_vo/solvers/relpose_homography.h"
#include "hybrid_vo/synthetic/minimal_instances.h"
#include "solver_test_utils.h"

namespace hybrid_vo {
namespace {

using testing::all_valid;
using testing::best_error;

struct Corruption {
  std::string name;
  // Applies to a configuration? (needs points / lines / VPs)
  std::function<bool(const SolverInfo&)> applies;
  std::function<void(const SolverInfo&, MinimalSample*)> apply;
  // Must the solver return no pose at all?
  bool expect_none;
};

std::vector<Corruption> corruptions() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  return {
      {"nan_point", [](const SolverInfo& i) { return i.num_points > 0; },
       [nan](const SolverInfo&, MinimalSample* s) { s->x1[0].x() = nan; }, false},
      {"inf_point_in_second_image", [](const SolverInfo& i) { return i.num_points > 0; },
       [inf](const SolverInfo&, MinimalSample* s) { s->x2[0].y() = inf; }, false},
      {"nan_segment", [](const SolverInfo& i) { return i.num_lines > 0; },
       [nan](const SolverInfo&, MinimalSample* s) { s->s2[0].p1.y() = nan; }, false},
      {"nan_vp", [](const SolverInfo& i) { return i.num_vps > 0; },
       [nan](const SolverInfo&, MinimalSample* s) { s->v1[0].z() = nan; }, true},
      {"zero_vp", [](const SolverInfo& i) { return i.num_vps > 0; },
       [](const SolverInfo&, MinimalSample* s) { s->v2[0].setZero(); }, true},
      {"repeated_point", [](const SolverInfo& i) { return i.num_points >= 2; },
       [](const SolverInfo&, MinimalSample* s) {
         s->x1[1] = s->x1[0];
         s->x2[1] = s->x2[0];
       },
       false},
      {"collinear_points", [](const SolverInfo& i) { return i.num_points >= 3; },
       [](const SolverInfo&, MinimalSample* s) {
         s->x1[2] = 0.3 * s->x1[0] + 0.7 * s->x1[1];
         s->x2[2] = 0.3 * s->x2[0] + 0.7 * s->x2[1];
       },
       false},
      {"zero_length_segment", [](const SolverInfo& i) { return i.num_lines > 0; },
       [](const SolverInfo&, MinimalSample* s) {
         s->s1[0].p2 = s->s1[0].p1;
         s->s2[0].p2 = s->s2[0].p1;
       },
       true},
      {"parallel_segments", [](const SolverInfo& i) { return i.num_lines >= 2; },
       [](const SolverInfo&, MinimalSample* s) {
         for (LineSegment* seg : {&s->s1[1], &s->s2[1]}) {
           const LineSegment& ref = seg == &s->s1[1] ? s->s1[0] : s->s2[0];
           const Eigen::Vector2d offset(0.05, -0.13);
           *seg = LineSegment(ref.p1 + offset, ref.p2 + offset);
         }
       },
       false},
      {"identical_segments", [](const SolverInfo& i) { return i.num_lines >= 2; },
       [](const SolverInfo&, MinimalSample* s) {
         s->s1[1] = s->s1[0];
         s->s2[1] = s->s2[0];
       },
       false},
      {"parallel_vps", [](const SolverInfo& i) { return i.num_vps == 2; },
       [](const SolverInfo&, MinimalSample* s) {
         s->v1[1] = s->v1[0];
         s->v2[1] = -s->v2[0];
       },
       true},
      {"all_zero", [](const SolverInfo&) { return true; },
       [](const SolverInfo&, MinimalSample* s) { *s = MinimalSample(); }, false},
  };
}

class DegenerateInputTest : public ::testing::TestWithParam<SolverId> {};

TEST_P(DegenerateInputTest, NoNanNoCrash) {
  const SolverInfo& info = solver_info(GetParam());
  std::mt19937_64 rng(500 + static_cast<int>(GetParam()));
  RelativePoses poses;
  for (const Corruption& c : corruptions()) {
    if (!c.applies(info)) continue;
    for (int trial = 0; trial < 50; ++trial) {
      MinimalInstance instance = generate_minimal_instance(GetParam(), rng);
      c.apply(info, &instance.sample);
      const int n = solve_minimal(GetParam(), instance.sample, &poses);
      EXPECT_EQ(n, static_cast<int>(poses.size())) << c.name;
      EXPECT_TRUE(all_valid(poses)) << info.code << " " << c.name;
      if (c.expect_none) EXPECT_EQ(n, 0) << info.code << " " << c.name;
    }
  }
}

// A VP at the image centre (direction along the optical axis) or at infinity (in the image plane)
// is an ordinary direction: solvers whose data do not depend on the VP still find the truth.
using VpDirectionTest = DegenerateInputTest;

TEST_P(VpDirectionTest, VpAtImageCentreAndAtInfinity) {
  const SolverInfo& info = solver_info(GetParam());
  const bool vp_independent_data = !info.orthogonal;
  std::mt19937_64 rng(600 + static_cast<int>(GetParam()));
  RelativePoses poses;
  const Eigen::Vector3d directions[2] = {Eigen::Vector3d::UnitZ(),
                                         Eigen::Vector3d(1.0, 0.3, 0.0).normalized()};
  for (int which = 0; which < 2; ++which) {
    int found = 0;
    const int trials = 200;
    for (int trial = 0; trial < trials; ++trial) {
      MinimalInstance instance = generate_minimal_instance(GetParam(), rng);
      MinimalSample& s = instance.sample;
      s.v1[0] = directions[which];
      s.v2[0] = instance.truth.R * directions[which];
      if (info.num_vps == 2) {
        s.v1[1] = directions[1 - which];
        s.v2[1] = instance.truth.R * directions[1 - which];
      }
      solve_minimal(GetParam(), s, &poses);
      EXPECT_TRUE(all_valid(poses)) << info.code;
      const auto e = best_error(poses, instance.truth);
      if (e.rotation < 1e-6 && e.translation < 1e-6) ++found;
    }
    if (vp_independent_data) EXPECT_GE(found, 0.99 * trials) << info.code << " vp " << which;
  }
}

INSTANTIATE_TEST_SUITE_P(AllConfigurations, DegenerateInputTest,
                         ::testing::ValuesIn(testing::all_solvers()), testing::solver_name);
INSTANTIATE_TEST_SUITE_P(WithVanishingPoints, VpDirectionTest,
                         ::testing::ValuesIn(testing::vp_solvers()), testing::solver_name);

}  // namespace
}  // namespace hybrid_vo

namespace hybrid_vo {
namespace {

// 2-2-0 is degenerate for every input: with q the junction of the two lines and m the line
// through the two points (image 1), every homology G(s) = I + s q m^T fixes both points and both
// lines, so H G(s) fits the data for all s and decomposes into different poses (HZ2004 Sec. 4.1.4
// notes the same for the projective DLT). The solver must report no pose rather than one of them.
TEST(HomographyDegeneracy, TwoPointsTwoLinesFitAOneParameterFamily) {
  std::mt19937_64 rng(700);
  for (int trial = 0; trial < 50; ++trial) {
    const MinimalInstance planar = generate_minimal_instance(SolverId::kHomography4pt, rng);
    const MinimalSample& p = planar.sample;
    Eigen::Matrix3d H;
    ASSERT_TRUE(homography_from_points_and_lines(p.x1.data(), p.x2.data(), 4, nullptr, nullptr, 0,
                                                 &H));
    // Two plane points and two plane lines (segments between image points, mapped by H).
    MinimalSample s;
    s.x1 = p.x1;
    s.x2 = p.x2;
    std::uniform_real_distribution<double> u(-0.3, 0.3);
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d a(u(rng), u(rng)), b(u(rng), u(rng));
      s.s1[k] = LineSegment(a, b);
      s.s2[k] = LineSegment((H * homogeneous(a)).hnormalized(), (H * homogeneous(b)).hnormalized());
    }
    RelativePoses poses;
    EXPECT_EQ(solve_minimal(SolverId::kHomography2pt2l, s, &poses), 0);
    Eigen::Matrix3d unused;
    EXPECT_FALSE(homography_from_points_and_lines(s.x1.data(), s.x2.data(), 2, s.s1.data(),
                                                  s.s2.data(), 2, &unused));

    const Eigen::Vector3d q = s.s1[0].line().cross(s.s1[1].line());
    const Eigen::Vector3d m = homogeneous(s.x1[0]).cross(homogeneous(s.x1[1]));
    std::vector<Eigen::Matrix3d> rotations;
    for (double step : {0.0, 0.3, -0.5}) {
      const Eigen::Matrix3d Hs =
          H * (Eigen::Matrix3d::Identity() + step * q * m.transpose() / (q.norm() * m.norm()));
      // Hs maps both points and both lines exactly.
      for (int k = 0; k < 2; ++k) {
        EXPECT_LT(((Hs * homogeneous(s.x1[k])).hnormalized() - s.x2[k]).norm(), 1e-9);
        const Eigen::Vector3d back = Hs.transpose() * s.s2[k].line();
        EXPECT_LT(back.normalized().cross(s.s1[k].line().normalized()).norm(), 1e-9);
      }
      PlanarMotion motions[4];
      Eigen::Matrix3d oriented = Hs;
      ASSERT_TRUE(orient_homography(&oriented, s.x1.data(), s.x2.data(), 2));
      ASSERT_EQ(decompose_homography(oriented, motions), 4);
      rotations.push_back(motions[0].R);
    }
    EXPECT_GT(rotation_error(rotations[0], rotations[1]), 1e-3);
    EXPECT_GT(rotation_error(rotations[0], rotations[2]), 1e-3);
  }
}

}  // namespace
}  // namespace hybrid_vo
