// The covariance a pair reports: the spread of competing rotations, the weighing of the sources
// (points, segments, priors) with the VP directions marginalised, bad input; and on random
// synthetic scenes, that it covers the error and never claims more than the refinement.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/estimation/pair_covariance.h"
#include "hybrid_vo/estimation/relative_pose_estimator.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/synthetic/manhattan_scene.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;
using Spread = Eigen::Matrix<double, 5, 5>;

TEST(RotationSpread, WeighsCompetingRotationsByTheirCost) {
  const Eigen::Matrix3d R = rotation_about(Eigen::Vector3d(1, 2, 3).normalized(), 0.3);
  EXPECT_TRUE(rotation_spread({}, R, 10.0, 1.0).isZero());
  // Two rotations 1 degree either side about x, as cheap as the best: with R itself, a third of
  // the weight each at 1 degree.
  const double a = 1.0 * kDeg;
  std::vector<PoseHypothesis> two = {
      {rotation_about(Eigen::Vector3d::UnitX(), a) * R, 10.0},
      {rotation_about(Eigen::Vector3d::UnitX(), -a) * R, 10.0}};
  const Eigen::Matrix3d spread = rotation_spread(two, R, 10.0, 1.0);
  EXPECT_NEAR(spread(0, 0), 2.0 / 3.0 * a * a, 1e-12);
  EXPECT_NEAR(spread(1, 1), 0.0, 1e-15);
  // Far more costly than the best, at this temperature: nearly nothing.
  for (PoseHypothesis& h : two) h.cost = 40.0;
  EXPECT_LT(rotation_spread(two, R, 10.0, 1.0)(0, 0), 1e-9 * a * a);
  // A hotter temperature weighs them in again.
  EXPECT_GT(rotation_spread(two, R, 10.0, 100.0)(0, 0), 0.5 * a * a);
  // Non-finite hypotheses are skipped, a bad temperature or R gives zero.
  two.push_back({Eigen::Matrix3d::Constant(NAN), 10.0});
  two.push_back({R, NAN});
  EXPECT_TRUE(all_finite(rotation_spread(two, R, 10.0, 100.0)));
  EXPECT_TRUE(rotation_spread(two, R, 10.0, 0.0).isZero());
  EXPECT_TRUE(rotation_spread(two, Eigen::Matrix3d::Constant(NAN), 10.0, 1.0).isZero());
}

TEST(HypothesisTemperature, TemperedByTheMatchesThatAreNotIndependent) {
  // 2 (sigma / threshold)^2, times matches / independent when there are more.
  EXPECT_NEAR(hypothesis_temperature(10, 20, 0.5, 1.0), 0.5, 1e-15);
  EXPECT_NEAR(hypothesis_temperature(400, 20, 0.5, 1.0), 10.0, 1e-12);
  EXPECT_EQ(hypothesis_temperature(400, 20, 0.5, 0.0), 0.0);
  EXPECT_EQ(hypothesis_temperature(400, 0, 0.5, 1.0), 0.0);
}

InformationSplit diagonal_split(int directions) {
  const int n = 5 + 2 * directions;
  InformationSplit split;
  split.valid = true;
  split.points_covariance = Eigen::Matrix<double, 5, 5>::Identity() * 1e-4;
  split.segment_information = Eigen::MatrixXd::Zero(n, n);
  split.prior_information = Eigen::MatrixXd::Zero(n, n);
  split.to_pose.topLeftCorner<3, 3>().setIdentity();
  split.to_pose.bottomRightCorner<3, 2>() << 1, 0, 0, 1, 0, 0;
  return split;
}

TEST(PairCovariance, WeighsTheSourcesAndMarginalisesTheDirections) {
  PairCovarianceOptions options;
  options.independent_points = 100.0;
  options.independent_segments = 10.0;
  Eigen::Matrix<double, 6, 6> C;
  // Points alone: their covariance times matches / independent, the spread on the rotation.
  InformationSplit split = diagonal_split(0);
  Spread spread = Spread::Zero();
  spread.topLeftCorner<3, 3>() = 2e-4 * Eigen::Matrix3d::Identity();
  ASSERT_TRUE(pair_covariance(split, spread, 400.0, 0.0, options, &C));
  EXPECT_NEAR(C(0, 0), 4e-4 + 2e-4, 1e-15);
  EXPECT_NEAR(C(3, 3), 4e-4, 1e-15);
  EXPECT_NEAR(C(5, 5), 0.0, 1e-15);  // nothing along t
  // A direction whose segments tie it to the rotation about x (information 1e4 between w_x and
  // the direction's first coordinate, 1e4 on the direction itself): marginalised, that is only
  // information where the direction is also held, here by a prior on it of 1e4.
  split = diagonal_split(1);
  split.segment_information(0, 0) = 1e4;
  split.segment_information(0, 5) = split.segment_information(5, 0) = -1e4;
  split.segment_information(5, 5) = 1e4;
  ASSERT_TRUE(pair_covariance(split, Spread::Zero(), 100.0, 10.0, options, &C));
  EXPECT_NEAR(C(0, 0), 1e-4, 1e-12);  // the direction free: the segments alone fix nothing
  split.prior_information(5, 5) = 1e4;
  ASSERT_TRUE(pair_covariance(split, Spread::Zero(), 100.0, 10.0, options, &C));
  // The segments and the prior in series give w_x 1 / (1 / 1e4 + 1 / 1e4) = 5e3, the points 1e4
  // beside them.
  EXPECT_NEAR(C(0, 0), 1.0 / 1.5e4, 1e-9);
  // Twenty segments count as ten: their information halves.
  ASSERT_TRUE(pair_covariance(split, Spread::Zero(), 100.0, 20.0, options, &C));
  const double segments = 0.5e4, chain = 1.0 / (1.0 / segments + 1.0 / 1e4);
  EXPECT_NEAR(C(0, 0), 1.0 / (1e4 + chain), 1e-9);
}

TEST(PairCovariance, BadInputIsNoCovariance) {
  PairCovarianceOptions options;
  Eigen::Matrix<double, 6, 6> C;
  InformationSplit split = diagonal_split(0);
  split.valid = false;
  EXPECT_FALSE(pair_covariance(split, Spread::Zero(), 100, 0, options, &C));
  EXPECT_TRUE(C.isZero());
  split = diagonal_split(0);
  EXPECT_FALSE(pair_covariance(split, Spread::Constant(NAN), 100, 0, options, &C));
  split.points_covariance(1, 1) = -1.0;  // not a covariance
  EXPECT_FALSE(pair_covariance(split, Spread::Zero(), 100, 0, options, &C));
  split = diagonal_split(1);
  split.prior_information.resize(5, 5);  // sizes that disagree
  EXPECT_FALSE(pair_covariance(split, Spread::Zero(), 100, 0, options, &C));
}

double rotation_nees(const RelativePoseEstimate& est, const Eigen::Matrix3d& truth,
                     const Eigen::Matrix<double, 6, 6>& covariance) {
  const Eigen::AngleAxisd error(Eigen::Matrix3d(est.pose.R * truth.transpose()));
  const Eigen::Vector3d w = error.angle() * error.axis();
  return w.dot(covariance.topLeftCorner<3, 3>().ldlt().solve(w));
}

// Random synthetic scenes with independent noise and outliers: the reported covariance covers
// the rotation's error. It was made for errors the residuals cannot show, which these scenes do
// not have, so here it is on the safe side, but not absurdly so.
TEST(PairCovariance, CoversTheErrorOnRandomScenes) {
  std::mt19937_64 rng(11);
  RelativePoseEstimatorOptions options;
  preset_options("hybrid+junc", &options);
  options.ransac.point_threshold_px = 1.5;
  std::vector<double> nees;
  for (int scene = 0; scene < 40; ++scene) {
    ManhattanSceneOptions scene_options;
    scene_options.noise_px = 0.5;
    scene_options.point_outlier_ratio = 0.2;
    scene_options.lines_per_vp_fit = 10;
    const ManhattanScene s = generate_manhattan_scene(rng, scene_options);
    options.ransac.seed = scene;
    const RelativePoseEstimate est =
        estimate_relative_pose(s.camera1, s.camera2, s.matches, options);
    ASSERT_EQ(est.status, EstimationStatus::kOk);
    ASSERT_TRUE(est.covariance_valid);
    nees.push_back(rotation_nees(est, s.truth.R, est.covariance));
  }
  int inside = 0;
  for (const double n : nees) inside += n < 7.815;
  EXPECT_GE(inside, 38);  // 95 % of 40
  std::nth_element(nees.begin(), nees.begin() + 20, nees.end());
  EXPECT_GT(nees[20], 0.1);  // the median: 2.37 if exact
}

// A plane: its points fit two motions, and RANSAC's hypotheses say so where the local curvature
// does not; the spread grows the rotation's covariance beyond the refinement's.
TEST(PairCovariance, APlaneWidensTheRotationBeyondItsCurvature) {
  std::mt19937_64 rng(12);
  RelativePoseEstimatorOptions options;
  preset_options("5pc", &options);
  int widened = 0;
  for (int scene = 0; scene < 10; ++scene) {
    ManhattanSceneOptions scene_options;
    scene_options.planar_point_fraction = 1.0;
    scene_options.noise_px = 1.0;
    scene_options.num_vps = 0;
    const ManhattanScene s = generate_manhattan_scene(rng, scene_options);
    const RelativePoseEstimate est =
        estimate_relative_pose(s.camera1, s.camera2, s.matches, options);
    if (est.status != EstimationStatus::kOk || !est.covariance_valid) continue;
    widened += est.rotation_spread.trace() > est.hessian_covariance.topLeftCorner<3, 3>().trace();
  }
  EXPECT_GE(widened, 5);
}

}  // namespace
}  // namespace hybrid_vo
