// The NEES measures behind the tools' `# consistency:` lines: errors drawn from a known
// covariance give the chi-square's median and 95 % inside, a covariance three times too small
// in sigma nine times the median, the truth's own noise is accounted for, unusable covariances
// are counted as missing, and an odometry covariance about the odom frame's axes for a body
// rotated against the camera is mapped into the first camera's frame.
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/evaluation/consistency.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace evaluation {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kSamples = 4000;

Eigen::Matrix3d exp_rotation(const Eigen::Vector3d& w) {
  return w.norm() > 0.0 ? rotation_about(w.normalized(), w.norm()) : Eigen::Matrix3d::Identity();
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
      .normalized()
      .toRotationMatrix();
}

// A random covariance with sigmas from `low` to `high` (rad) about random axes.
Eigen::Matrix3d random_covariance(std::mt19937& rng, double low, double high) {
  std::uniform_real_distribution<double> sigma(low, high);
  const Eigen::Matrix3d R = random_rotation(rng);
  const Eigen::Vector3d s(sigma(rng), sigma(rng), sigma(rng));
  return R * s.cwiseAbs2().asDiagonal() * R.transpose();
}

template <int N>
Eigen::Matrix<double, N, 1> draw(std::mt19937& rng, const Eigen::Matrix<double, N, N>& C) {
  std::normal_distribution<double> normal;
  Eigen::Matrix<double, N, 1> z;
  for (int i = 0; i < N; ++i) z(i) = normal(rng);
  return Eigen::LLT<Eigen::Matrix<double, N, N>>(C).matrixL() * z;
}

// NEES of rotations with errors drawn from a random covariance C, judged under
// reported_scale^2 C, against a truth off by its own noise of truth_sigma per axis.
std::vector<double> rotation_samples(unsigned seed, double reported_scale, double truth_sigma,
                                     double assumed_truth_sigma) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<double> nees;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Matrix3d C = random_covariance(rng, 0.05 * kDeg, 2.0 * kDeg);
    const Eigen::Matrix3d R_true = random_rotation(rng);
    const Eigen::Matrix3d R_est = exp_rotation(draw<3>(rng, C)) * R_true;
    const Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
    const Eigen::Matrix3d R_measured = exp_rotation(truth_sigma * v) * R_true;
    nees.push_back(rotation_nees(R_est, R_measured, reported_scale * reported_scale * C,
                                 assumed_truth_sigma));
  }
  return nees;
}

TEST(Consistency, HonestRotationCovarianceGivesTheChiSquare) {
  const NeesSummary s = summarize_nees(rotation_samples(1, 1.0, 0.0, 0.0), 3);
  EXPECT_EQ(s.count, kSamples);
  EXPECT_EQ(s.missing, 0);
  EXPECT_NEAR(s.median, 2.366, 0.15);
  EXPECT_NEAR(s.inside95, 0.95, 0.015);
  EXPECT_NEAR(s.p90, 6.251, 0.5);  // chi-square 3 dof, 90 %
}

TEST(Consistency, RotationCovarianceThreeTimesTooSmallGivesNineTimesTheMedian) {
  const NeesSummary s = summarize_nees(rotation_samples(2, 1.0 / 3.0, 0.0, 0.0), 3);
  EXPECT_NEAR(s.median / 2.366, 9.0, 0.9);
  EXPECT_LT(s.inside95, 0.45);
}

TEST(Consistency, RotationTruthNoiseIsAddedToTheCovariance) {
  const double sigma = 1.0 * kDeg;  // about the estimate's own
  const NeesSummary ignored = summarize_nees(rotation_samples(3, 1.0, sigma, 0.0), 3);
  const NeesSummary added = summarize_nees(rotation_samples(3, 1.0, sigma, sigma), 3);
  EXPECT_GT(ignored.median, 4.0);
  EXPECT_NEAR(added.median, 2.366, 0.15);
  EXPECT_NEAR(added.inside95, 0.95, 0.015);
}

// Directions: the error drawn in the tangent plane of the true direction, the covariance of t
// (rank 2, nothing along t) reported for unit t or, scaled by `length`, for metric t with a
// variance along t.
std::vector<double> direction_samples(unsigned seed, double reported_scale, double truth_sigma,
                                      double assumed_truth_sigma, double length) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> sigma(0.1 * kDeg, 2.0 * kDeg);
  std::vector<double> nees;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector3d d_true =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    Eigen::Matrix<double, 3, 2> B;
    B.col(0) = d_true.unitOrthogonal();
    B.col(1) = d_true.cross(B.col(0));
    const Eigen::Matrix2d Q = Eigen::Rotation2Dd(2.0 * M_PI * (i % 97) / 97.0).toRotationMatrix();
    const Eigen::Vector2d s(sigma(rng), sigma(rng));
    const Eigen::Matrix2d C2 = Q * s.cwiseAbs2().asDiagonal() * Q.transpose();
    const Eigen::Vector3d step = B * draw<2>(rng, C2);
    const Eigen::Vector3d d_est =
        exp_rotation(d_true.cross(step.normalized()) * step.norm()) * d_true;
    Eigen::Matrix3d C = reported_scale * reported_scale * length * length * B * C2 * B.transpose();
    if (length != 1.0) C += 0.1 * length * length * d_est * d_est.transpose();
    const Eigen::Vector3d noise = B * Eigen::Vector2d(normal(rng), normal(rng)) * truth_sigma;
    const Eigen::Vector3d d_measured =
        exp_rotation(d_true.cross(noise.normalized()) * noise.norm()) * d_true;
    nees.push_back(direction_nees(length * d_est, d_measured, C, assumed_truth_sigma));
  }
  return nees;
}

TEST(Consistency, HonestDirectionCovarianceGivesTheChiSquare) {
  for (double length : {1.0, 0.8}) {
    const NeesSummary s = summarize_nees(direction_samples(4, 1.0, 0.0, 0.0, length), 2);
    EXPECT_EQ(s.missing, 0);
    EXPECT_NEAR(s.median, 1.386, 0.1) << "length " << length;
    EXPECT_NEAR(s.inside95, 0.95, 0.015) << "length " << length;
  }
}

TEST(Consistency, DirectionCovarianceThreeTimesTooSmallGivesNineTimesTheMedian) {
  const NeesSummary s = summarize_nees(direction_samples(5, 1.0 / 3.0, 0.0, 0.0, 1.0), 2);
  EXPECT_NEAR(s.median / 1.386, 9.0, 0.9);
  EXPECT_LT(s.inside95, 0.45);
}

TEST(Consistency, DirectionTruthNoiseIsAddedInTheTangentPlane) {
  const double sigma = 1.0 * kDeg;
  const NeesSummary ignored = summarize_nees(direction_samples(6, 1.0, sigma, 0.0, 1.0), 2);
  const NeesSummary added = summarize_nees(direction_samples(6, 1.0, sigma, sigma, 1.0), 2);
  EXPECT_GT(ignored.median, 2.5);
  EXPECT_NEAR(added.median, 1.386, 0.1);
  EXPECT_NEAR(added.inside95, 0.95, 0.015);
}

TEST(Consistency, DirectionErrorIsTheAngleOnTheSphere) {
  // 10 degrees off under 1 degree per axis: (10 / 1)^2, whatever the length of t.
  const Eigen::Vector3d t_true(0.0, 0.0, 1.0);
  const Eigen::Vector3d t_est = 3.0 * exp_rotation(Eigen::Vector3d(10.0 * kDeg, 0.0, 0.0)) * t_true;
  const Eigen::Matrix3d C = 9.0 * kDeg * kDeg * Eigen::Matrix3d::Identity();
  EXPECT_NEAR(direction_nees(t_est, t_true, C), 100.0, 1e-6);
  EXPECT_EQ(direction_nees(-t_true, t_true, C), std::numeric_limits<double>::infinity());
  EXPECT_NEAR(direction_nees(t_true, t_true, C), 0.0, 1e-12);
}

// A world direction seen by two cameras, each observation off by its own random tangent
// covariance, a's sign drawn at random (a VP's sign is arbitrary); judged with each covariance
// times `reported_scale`^2.
std::vector<double> direction_pair_samples(unsigned seed, double reported_scale) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> sigma(0.05 * kDeg, 1.0 * kDeg);
  auto observe = [&](const Eigen::Vector3d& d, Eigen::Matrix3d* C) {
    Eigen::Matrix<double, 3, 2> B;
    B.col(0) = d.unitOrthogonal();
    B.col(1) = d.cross(B.col(0));
    const Eigen::Vector2d s(sigma(rng), sigma(rng));
    const Eigen::Matrix2d C2 = s.cwiseAbs2().asDiagonal();
    *C = reported_scale * reported_scale * B * C2 * B.transpose();
    const Eigen::Vector3d step = B * draw<2>(rng, C2);
    return Eigen::Vector3d(exp_rotation(d.cross(step.normalized()) * step.norm()) * d);
  };
  std::vector<double> nees;
  for (int i = 0; i < kSamples; ++i) {
    const Eigen::Vector3d world = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Matrix3d R_a = random_rotation(rng), R_b = random_rotation(rng);  // world from camera
    Eigen::Matrix3d C_a, C_b;
    const Eigen::Vector3d d_a = (i % 2 ? -1.0 : 2.5) * observe(R_a.transpose() * world, &C_a);
    const Eigen::Vector3d d_b = observe(R_b.transpose() * world, &C_b);
    nees.push_back(direction_pair_nees(d_a, C_a, d_b, C_b, R_b.transpose() * R_a));
  }
  return nees;
}

TEST(Consistency, HonestDirectionPairGivesTheChiSquareWhateverTheSign) {
  const NeesSummary s = summarize_nees(direction_pair_samples(5, 1.0), 2);
  EXPECT_EQ(s.missing, 0);
  EXPECT_NEAR(s.median, 1.386, 0.1);
  EXPECT_NEAR(s.inside95, 0.95, 0.015);
  // Covariances a third too small in sigma: nine times the NEES.
  EXPECT_NEAR(summarize_nees(direction_pair_samples(5, 1.0 / 3.0), 2).median, 9 * 1.386, 1.0);
}

TEST(Consistency, DirectionPairWithoutAUsableCovarianceIsMissing) {
  const Eigen::Vector3d d(0.0, 0.0, 1.0);
  const Eigen::Matrix3d C = 1e-4 * (Eigen::Matrix3d::Identity() - d * d.transpose());
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  EXPECT_NEAR(direction_pair_nees(d, C, d, C, I), 0.0, 1e-12);
  EXPECT_TRUE(std::isnan(direction_pair_nees(d, Eigen::Matrix3d::Zero(), d,
                                             Eigen::Matrix3d::Zero(), I)));
  EXPECT_TRUE(std::isnan(direction_pair_nees(Eigen::Vector3d::Zero(), C, d, C, I)));
  EXPECT_TRUE(std::isnan(direction_pair_nees(d, C, Eigen::Vector3d::Constant(NAN), C, I)));
  EXPECT_TRUE(std::isnan(direction_pair_nees(d, C, d, C, Eigen::Matrix3d::Constant(NAN))));
}

TEST(Consistency, SightingsAreComparedAtLeastTheGapApartPerDirection) {
  DirectionSightings sightings(5);
  const Eigen::Matrix3d C = 1e-6 * Eigen::Matrix3d::Identity();
  std::mt19937 rng(9);
  std::vector<Eigen::Matrix3d> R_true;
  for (int frame = 0; frame <= 12; ++frame) {
    R_true.push_back(random_rotation(rng));
    // Direction 0 exact at every frame, direction 1 (from frame 3 on) 1 mrad off at frame 8.
    sightings.add(frame, 0, R_true[frame].transpose() * Eigen::Vector3d::UnitX(), C, R_true[frame]);
    if (frame >= 3) {
      Eigen::Vector3d d = R_true[frame].transpose() * Eigen::Vector3d::UnitY();
      if (frame == 8) d = exp_rotation(1e-3 * R_true[frame].transpose() * Eigen::Vector3d::UnitZ()) * d;
      sightings.add(frame, 1, d, C, R_true[frame]);
    }
  }
  // In the order compared: direction 0 at 5 (against 0), 1 at 8 (against 3), 0 at 10 (against 5).
  ASSERT_EQ(sightings.nees().size(), 3u);
  EXPECT_NEAR(sightings.nees()[0], 0.0, 1e-9);
  EXPECT_NEAR(sightings.nees()[1], 1e-6 / 2e-6, 1e-3);  // (1 mrad)^2 over both covariances
  EXPECT_NEAR(sightings.nees()[2], 0.0, 1e-9);
}

TEST(Consistency, UnusableCovariancesAreMissingNeverACrash) {
  const Eigen::Matrix3d R = exp_rotation(Eigen::Vector3d(0.01, -0.02, 0.03));
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d t(0.0, 0.0, 1.0);
  Eigen::Matrix3d nan_entry = 1e-4 * I;
  nan_entry(1, 1) = NAN;
  Eigen::Matrix3d inf_entry = 1e-4 * I;
  inf_entry(0, 2) = inf_entry(2, 0) = INFINITY;
  Eigen::Matrix3d asymmetric = 1e-4 * I;
  asymmetric(0, 1) = 5e-5;
  const Eigen::Matrix3d negative = Eigen::Vector3d(1e-4, 1e-4, -1e-4).asDiagonal();
  const Eigen::Matrix3d rank2 = Eigen::Vector3d(1e-4, 1e-4, 0.0).asDiagonal();
  const Eigen::Matrix3d rank1 = Eigen::Vector3d(1e-4, 0.0, 0.0).asDiagonal();
  for (const Eigen::Matrix3d& C :
       {Eigen::Matrix3d(Eigen::Matrix3d::Zero()), nan_entry, inf_entry, asymmetric, negative,
        rank2}) {
    // The truth's noise is no covariance of the estimate: it does not make one usable.
    EXPECT_TRUE(std::isnan(rotation_nees(R, I, C))) << C;
    EXPECT_TRUE(std::isnan(rotation_nees(R, I, C, 0.01))) << C;
    EXPECT_TRUE(std::isnan(orientation_nees(I, R, I, I, C, 0.01))) << C;
  }
  // Rank 2 serves a direction when nothing is missing across t; rank 1, or the null space in
  // the tangent plane, does not.
  EXPECT_FALSE(std::isnan(direction_nees(t, R * t, rank2)));
  const Eigen::Matrix3d tangent_null = Eigen::Vector3d(0.0, 1e-4, 1e-4).asDiagonal();
  for (const Eigen::Matrix3d& C :
       {Eigen::Matrix3d(Eigen::Matrix3d::Zero()), nan_entry, inf_entry, asymmetric, negative,
        rank1, tangent_null})
    EXPECT_TRUE(std::isnan(direction_nees(t, R * t, C, 0.01))) << C;
  EXPECT_TRUE(std::isnan(direction_nees(Eigen::Vector3d::Zero(), t, I)));
  EXPECT_TRUE(std::isnan(direction_nees(t, Eigen::Vector3d::Zero(), I)));
  EXPECT_TRUE(std::isnan(rotation_nees(R, Eigen::Matrix3d::Constant(NAN), I)));
  EXPECT_FALSE(usable_covariance(Eigen::MatrixXd(0, 0), 1));
  EXPECT_FALSE(usable_covariance(Eigen::MatrixXd::Identity(3, 2), 2));

  const NeesSummary s = summarize_nees({NAN, 1.0, NAN, 9.0, 3.0}, 3);
  EXPECT_EQ(s.count, 5);
  EXPECT_EQ(s.missing, 2);
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.inside95, 2.0 / 3.0);
  const NeesSummary none = summarize_nees({NAN, NAN}, 2);
  EXPECT_EQ(none.missing, 2);
  EXPECT_TRUE(std::isnan(none.median));
  EXPECT_TRUE(std::isnan(none.inside95));
  EXPECT_EQ(describe_nees(none, "pairs"), "NEES: none of 2 pairs with a covariance");
  EXPECT_EQ(describe_nees(s, "pairs"),
            "NEES median 3.00 (honest 2.366), p90 9.00, 66.7 % inside the 95 % ellipsoid "
            "(7.815); 3 of 5 pairs with a covariance");
}

TEST(Consistency, MessageBlocks) {
  // nav_msgs/Odometry: [x y z, rotation]; hybrid_vo/MotionEstimate: [rotation, translation].
  double row_major[36];
  for (int i = 0; i < 36; ++i) row_major[i] = i;
  const Eigen::Matrix3d rotation = covariance_block(row_major, 3);
  EXPECT_EQ(rotation(0, 0), 21.0);
  EXPECT_EQ(rotation(0, 2), 23.0);
  EXPECT_EQ(rotation(2, 0), 33.0);
  EXPECT_EQ(covariance_block(row_major, 0)(1, 2), 8.0);
}

// The node's odometry: odom is the body (base_link) at the first frame, the camera sits in the
// body through a static rotation (a KITTI-like camera, z forward, in a body with x forward and z
// up), and the pose covariance is of the body's orientation about the odom frame's axes. The
// evaluation maps the body's poses to camera poses through the static transform and compares
// them with the camera's truth, in a world of its own, against the first frame.
TEST(Consistency, OdometryCovarianceOfARotatedBodyIsMappedIntoTheFirstCamerasFrame) {
  std::mt19937 rng(7);
  Eigen::Matrix3d R_body_camera;
  R_body_camera << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  // Tight about odom's x and y, loose about its vertical z, as a ground vehicle's heading.
  const Eigen::Matrix3d C_odom = Eigen::Vector3d(0.05, 0.2, 3.0).cwiseAbs2().asDiagonal() *
                                 kDeg * kDeg;
  double row_major[36] = {};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) row_major[(3 + r) * 6 + 3 + c] = C_odom(r, c);
  const Eigen::Matrix3d C = covariance_block(row_major, 3);

  const Eigen::Matrix3d truth_0 = random_rotation(rng);  // camera to the truth's world
  const Eigen::Matrix3d camera_0 = R_body_camera;        // camera to odom: the body at frame 0
  std::vector<double> mapped, unmapped;
  for (int k = 0; k < kSamples; ++k) {
    const Eigen::Matrix3d truth_k = random_rotation(rng);
    const Eigen::Matrix3d body_k = R_body_camera * truth_0.transpose() * truth_k *
                                   R_body_camera.transpose();
    const Eigen::Matrix3d body_est = exp_rotation(draw<3>(rng, C_odom)) * body_k;
    const Eigen::Matrix3d camera_est = body_est * R_body_camera;
    mapped.push_back(orientation_nees(camera_0, camera_est, truth_0, truth_k, C));
    // The mistake this guards against: the odom-frame covariance taken as the first camera's.
    unmapped.push_back(rotation_nees(camera_0.transpose() * camera_est,
                                     truth_0.transpose() * truth_k, C));
  }
  const NeesSummary s = summarize_nees(mapped, 3);
  EXPECT_NEAR(s.median, 2.366, 0.15);
  EXPECT_NEAR(s.inside95, 0.95, 0.015);
  EXPECT_GT(summarize_nees(unmapped, 3).median, 10.0);
  // The error is the left increment seen from the first camera.
  const Eigen::Vector3d w(0.01, -0.002, 0.03);
  const RelativeOrientation o = relative_orientation(
      camera_0, exp_rotation(w) * camera_0 * truth_0.transpose() * truth_0, truth_0, truth_0, C);
  EXPECT_LT((o.error - camera_0.transpose() * w).norm(), 1e-12);
  EXPECT_LT((o.covariance - camera_0.transpose() * C_odom * camera_0).norm(), 1e-15);
}

}  // namespace
}  // namespace evaluation
}  // namespace hybrid_vo
