// The odometry's covariances (geometry/pose_covariance.h) against Monte-Carlo runs of the same
// chain: the pose accumulated over random pairs (with the orientation filter's step as the chain's
// prediction, as a correction by a measurement, and as added drift), the pose mapped into the
// body frame, and the twist of a pair; and what the chain does with missing or non-finite input.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/geometry/pose_covariance.h"

namespace hybrid_vo {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle == 0.0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d log_so3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd a(R);
  return a.angle() * a.axis();
}

Eigen::Vector3d normal3(std::mt19937_64& rng, double sigma = 1.0) {
  std::normal_distribution<double> n(0.0, sigma);
  return Eigen::Vector3d(n(rng), n(rng), n(rng));
}

// A random covariance with rotation-translation cross terms: standard deviations of the order of
// `sigma_a` in the first three coordinates and `sigma_b` in the last three.
Matrix6d random_covariance(std::mt19937_64& rng, double sigma_a, double sigma_b) {
  std::normal_distribution<double> n;
  Matrix6d A;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) A(i, j) = n(rng) * (i < 3 ? sigma_a : sigma_b);
  return A * A.transpose() / 6.0;
}

Eigen::Matrix3d random_covariance3(std::mt19937_64& rng, double sigma) {
  std::normal_distribution<double> n;
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = n(rng) * sigma;
  return A * A.transpose() / 3.0;
}

// Draws from N(0, C).
template <int N>
class Sampler {
 public:
  explicit Sampler(const Eigen::Matrix<double, N, N>& C) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> e(C);
    root_ = e.eigenvectors() * e.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  }
  Eigen::Matrix<double, N, 1> operator()(std::mt19937_64& rng) const {
    std::normal_distribution<double> n;
    Eigen::Matrix<double, N, 1> z;
    for (int i = 0; i < N; ++i) z(i) = n(rng);
    return root_ * z;
  }

 private:
  Eigen::Matrix<double, N, N> root_;
};

// The largest difference of a sample covariance from the expected one, relative to the expected
// standard deviations: |S_ij - A_ij| / sqrt(A_ii A_jj) (a difference of correlations).
double relative_difference(const Matrix6d& sample, const Matrix6d& expected) {
  double worst = 0.0;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      worst = std::max(worst, std::abs(sample(i, j) - expected(i, j)) /
                                  std::sqrt(expected(i, i) * expected(j, j)));
  return worst;
}

double position_variance(const Matrix6d& C) { return C.topLeftCorner<3, 3>().trace(); }

Matrix6d sample_covariance(const std::vector<Vector6d>& errors) {
  Vector6d mean = Vector6d::Zero();
  for (const Vector6d& e : errors) mean += e;
  mean /= errors.size();
  Matrix6d C = Matrix6d::Zero();
  for (const Vector6d& e : errors) C += (e - mean) * (e - mean).transpose();
  return C / (errors.size() - 1);
}

// How the orientation filter treats each pair's predicted orientation.
enum class FilterStep {
  kChain,      // keeps the chain's prediction
  kCorrected,  // corrects it by a measurement of the orientation (the map), a Kalman update
  kInflated,   // adds drift of its own (drift floor, blank wall)
  kAlternating,
};

// One pair of the chain and what the filter did with it.
struct Pair {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  Matrix6d covariance;
  bool corrected = false, inflated = false;
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero(), measurement = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d drift = Eigen::Matrix3d::Zero();
};

// A random pair of a chain: a turn of about 0.15 rad, a unit-sized step, its covariance.
Pair random_pair(std::mt19937_64& rng) {
  Pair p;
  p.R = exp_so3(normal3(rng, 0.15));
  p.t = normal3(rng);
  p.covariance = random_covariance(rng, 2e-3, 2e-2);
  return p;
}

// The accumulated pose covariance of a random chain of `steps` pairs, from
// propagate_pose_covariance and from a Monte-Carlo run of the chain itself; returns their
// relative difference.
double chain_against_monte_carlo(uint64_t seed, FilterStep mode, int steps, int samples,
                                 Matrix6d* analytic_out = nullptr) {
  std::mt19937_64 rng(seed);
  const Matrix6d start = random_covariance(rng, 1e-3, 1e-2);
  std::vector<Pair> pairs(steps);
  // The analytic chain, about the noiseless poses.
  Matrix6d analytic = start;
  Eigen::Matrix3d R_wc = exp_so3(normal3(rng, 0.5));
  const Eigen::Matrix3d R_wc0 = R_wc;
  for (int k = 0; k < steps; ++k) {
    Pair& p = pairs[k] = random_pair(rng);
    R_wc = R_wc * p.R.transpose();
    const Eigen::Matrix3d predicted = analytic.bottomRightCorner<3, 3>() +
                                      R_wc * p.covariance.topLeftCorner<3, 3>() *
                                          R_wc.transpose();
    Eigen::Matrix3d filtered = predicted;
    p.corrected = mode == FilterStep::kCorrected || (mode == FilterStep::kAlternating && k % 2);
    p.inflated = mode == FilterStep::kInflated || (mode == FilterStep::kAlternating && !(k % 2));
    if (p.corrected) {
      p.measurement = random_covariance3(rng, 3e-3);
      p.K = predicted * (predicted + p.measurement).inverse();
      filtered = (Eigen::Matrix3d::Identity() - p.K) * predicted;
      filtered = 0.5 * (filtered + filtered.transpose());
    } else if (p.inflated) {
      p.drift = random_covariance3(rng, 2e-3);
      filtered = predicted + p.drift;
    }
    Matrix6d next;
    EXPECT_TRUE(propagate_pose_covariance(analytic, R_wc, p.t, p.covariance, filtered, &next));
    analytic = next;
  }
  EXPECT_TRUE(is_covariance(analytic));
  if (analytic_out) *analytic_out = analytic;

  // The chain run with noise: the errors of the final pose against the noiseless one.
  const Sampler<6> start_error(start);
  std::vector<Sampler<6>> pair_error;
  std::vector<Sampler<3>> measurement_error, drift_error;
  for (const Pair& p : pairs) {
    pair_error.emplace_back(p.covariance);
    measurement_error.emplace_back(p.measurement);
    drift_error.emplace_back(p.drift);
  }
  std::vector<Vector6d> errors;
  for (int s = 0; s < samples; ++s) {
    const Vector6d e0 = start_error(rng);
    Eigen::Vector3d c = e0.head<3>(), c_true = Eigen::Vector3d::Zero();
    Eigen::Matrix3d R = exp_so3(e0.tail<3>()) * R_wc0, R_true = R_wc0;
    for (int k = 0; k < steps; ++k) {
      const Pair& p = pairs[k];
      const Vector6d n = pair_error[k](rng);
      const Eigen::Matrix3d R_pair = exp_so3(n.head<3>()) * p.R;
      const Eigen::Vector3d t_pair = p.t + n.tail<3>();
      R_true = R_true * p.R.transpose();
      R = R * R_pair.transpose();
      if (p.corrected || p.inflated) {
        Eigen::Vector3d e = log_so3(R * R_true.transpose());
        if (p.corrected)
          e = (Eigen::Matrix3d::Identity() - p.K) * e + p.K * measurement_error[k](rng);
        else
          e += drift_error[k](rng);
        R = exp_so3(e) * R_true;
      }
      // The position is integrated with the orientation the filter holds.
      c = c - R * t_pair;
      c_true = c_true - R_true * p.t;
    }
    Vector6d e;
    e << c - c_true, log_so3(R * R_true.transpose());
    errors.push_back(e);
  }
  return relative_difference(sample_covariance(errors), analytic);
}

TEST(PoseCovariance, ChainMatchesMonteCarlo) {
  for (const FilterStep mode : {FilterStep::kChain, FilterStep::kCorrected, FilterStep::kInflated,
                                FilterStep::kAlternating})
    for (uint64_t seed = 1; seed <= 3; ++seed) {
      const double difference = chain_against_monte_carlo(seed, mode, 8, 20000);
      EXPECT_LT(difference, 0.04) << "mode " << static_cast<int>(mode) << ", seed " << seed;
    }
}

// Leaving out the cross terms would show: the chain's position and rotation errors correlate.
TEST(PoseCovariance, ChainHasCrossTerms) {
  Matrix6d C;
  chain_against_monte_carlo(4, FilterStep::kChain, 8, 10, &C);
  const Eigen::Matrix3d cross = C.topRightCorner<3, 3>();
  EXPECT_GT(cross.norm(), 0.1 * std::sqrt(C.topLeftCorner<3, 3>().norm() *
                                          C.bottomRightCorner<3, 3>().norm()));
}

TEST(PoseCovariance, ExactPairsAddNothing) {
  std::mt19937_64 rng(5);
  const Eigen::Matrix3d R_wc = exp_so3(normal3(rng));
  const Eigen::Vector3d t = normal3(rng);
  Matrix6d out = Matrix6d::Constant(7.0);
  // An exact start and exact pairs stay exact.
  ASSERT_TRUE(propagate_pose_covariance(Matrix6d::Zero(), R_wc, t, Matrix6d::Zero(),
                                        Eigen::Matrix3d::Zero(), &out));
  EXPECT_EQ(out, Matrix6d::Zero());
  // An exact pair that does not move keeps any covariance as it was.
  const Matrix6d start = random_covariance(rng, 1e-3, 1e-2);
  ASSERT_TRUE(propagate_pose_covariance(start, R_wc, Eigen::Vector3d::Zero(), Matrix6d::Zero(),
                                        start.bottomRightCorner<3, 3>(), &out));
  EXPECT_LT((out - start).norm(), 1e-12 * start.norm());
  // An exact pair that moves swings the position by the orientation's uncertainty only.
  ASSERT_TRUE(propagate_pose_covariance(start, R_wc, t, Matrix6d::Zero(),
                                        start.bottomRightCorner<3, 3>(), &out));
  EXPECT_LT((out.bottomRightCorner<3, 3>() - start.bottomRightCorner<3, 3>()).norm(), 1e-15);
  EXPECT_GT(position_variance(out), position_variance(start));
}

TEST(PoseCovariance, ChainKeepsTheLastOnNonFiniteInputAndCountsIt) {
  std::mt19937_64 rng(6);
  PoseCovarianceChain chain;
  const Eigen::Matrix3d R_wc = exp_so3(normal3(rng));
  const Eigen::Vector3d t = normal3(rng);
  const Matrix6d pair = random_covariance(rng, 1e-3, 1e-2);
  const Eigen::Matrix3d orientation = R_wc * pair.topLeftCorner<3, 3>() * R_wc.transpose();
  chain.integrate(chain.covariance(), R_wc, t, &pair, orientation);
  const Matrix6d first = chain.covariance();
  EXPECT_TRUE(is_covariance(first));
  EXPECT_GT(first.trace(), 0.0);
  EXPECT_EQ(chain.gaps(), 0);

  Matrix6d nan_pair = pair;
  nan_pair(4, 4) = NAN;
  chain.integrate(chain.covariance(), R_wc, t, &nan_pair, orientation);
  EXPECT_EQ(chain.covariance(), first);
  EXPECT_EQ(chain.gaps(), 1);
  Eigen::Matrix3d nan_orientation = orientation;
  nan_orientation(0, 1) = INFINITY;
  chain.integrate(chain.covariance(), R_wc, t, &pair, nan_orientation);
  chain.integrate(chain.covariance(), R_wc, Eigen::Vector3d(NAN, 0, 0), &pair, orientation);
  EXPECT_EQ(chain.covariance(), first);
  EXPECT_EQ(chain.gaps(), 3);
  Matrix6d out = Matrix6d::Constant(3.0);
  EXPECT_FALSE(propagate_pose_covariance(first, R_wc, t, nan_pair, orientation, &out));
  EXPECT_EQ(out, Matrix6d::Constant(3.0));

  // A pair without a covariance: the position grows by the orientation's uncertainty alone.
  chain.integrate(chain.covariance(), R_wc, t, nullptr, first.bottomRightCorner<3, 3>());
  EXPECT_EQ(chain.gaps(), 4);
  EXPECT_TRUE(is_covariance(chain.covariance()));
  EXPECT_GT(position_variance(chain.covariance()), position_variance(first));

  chain.reset();
  EXPECT_EQ(chain.covariance(), Matrix6d::Zero());
  EXPECT_EQ(chain.gaps(), 4);
}

// A monocular chain whose unit drifts: each pair's translation is taken in its keyframe's unit
// (e^s times its own), and a pair that hands the unit on leaves the next keyframe's unit off by its
// own length error. The covariance of [position, rotation, log-scale] against Monte-Carlo runs.
TEST(PoseCovariance, ScaledChainMatchesMonteCarlo) {
  using Matrix7d = Eigen::Matrix<double, 7, 7>;
  using Vector7d = Eigen::Matrix<double, 7, 1>;
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    std::mt19937_64 rng(seed);
    const int steps = 8, samples = 20000;
    Matrix7d start = Matrix7d::Zero();
    start.topLeftCorner<6, 6>() = random_covariance(rng, 1e-3, 1e-2);
    start(6, 6) = 1e-4;
    std::vector<Pair> pairs(steps);
    std::vector<char> hands_on(steps);
    Matrix7d analytic = start;
    Eigen::Matrix3d R_wc = exp_so3(normal3(rng, 0.5));
    const Eigen::Matrix3d R_wc0 = R_wc;
    for (int k = 0; k < steps; ++k) {
      Pair& p = pairs[k] = random_pair(rng);
      hands_on[k] = k % 3 != 2;
      R_wc = R_wc * p.R.transpose();
      const Eigen::Matrix3d predicted = analytic.block<3, 3>(3, 3) +
                                        R_wc * p.covariance.topLeftCorner<3, 3>() * R_wc.transpose();
      Matrix7d next;
      ASSERT_TRUE(propagate_scaled_pose_covariance(analytic, R_wc, p.t, p.covariance, predicted,
                                                   hands_on[k], &next));
      analytic = next;
    }
    const Sampler<7> start_error(start);
    std::vector<Sampler<6>> pair_error;
    for (const Pair& p : pairs) pair_error.emplace_back(p.covariance);
    std::vector<Vector7d> errors;
    for (int n = 0; n < samples; ++n) {
      const Vector7d e0 = start_error(rng);
      Eigen::Vector3d c = e0.head<3>(), c_true = Eigen::Vector3d::Zero();
      Eigen::Matrix3d R = exp_so3(e0.segment<3>(3)) * R_wc0, R_true = R_wc0;
      double s = e0(6);
      for (int k = 0; k < steps; ++k) {
        const Pair& p = pairs[k];
        const Vector6d noise = pair_error[k](rng);
        const Eigen::Vector3d t_pair = p.t + noise.tail<3>();
        R_true = R_true * p.R.transpose();
        R = R * (exp_so3(noise.head<3>()) * p.R).transpose();
        c = c - R * t_pair * std::exp(s);
        c_true = c_true - R_true * p.t;
        if (hands_on[k]) s += std::log(t_pair.norm() / p.t.norm());
      }
      Vector7d e;
      e << c - c_true, log_so3(R * R_true.transpose()), s;
      errors.push_back(e);
    }
    Vector7d mean = Vector7d::Zero();
    for (const Vector7d& e : errors) mean += e;
    mean /= samples;
    Matrix7d sample = Matrix7d::Zero();
    for (const Vector7d& e : errors) sample += (e - mean) * (e - mean).transpose();
    sample /= samples - 1;
    double worst = 0.0;
    for (int i = 0; i < 7; ++i)
      for (int j = 0; j < 7; ++j)
        worst = std::max(worst, std::abs(sample(i, j) - analytic(i, j)) /
                                    std::sqrt(analytic(i, i) * analytic(j, j)));
    EXPECT_LT(worst, 0.05) << "seed " << seed;
    // The unit's drift is most of the position's uncertainty here: without it the chain claims
    // less.
    Matrix7d exact_unit = start;
    exact_unit(6, 6) = 0.0;
    R_wc = R_wc0;
    for (int k = 0; k < steps; ++k) {
      R_wc = R_wc * pairs[k].R.transpose();
      const Eigen::Matrix3d predicted =
          exact_unit.block<3, 3>(3, 3) +
          R_wc * pairs[k].covariance.topLeftCorner<3, 3>() * R_wc.transpose();
      ASSERT_TRUE(propagate_scaled_pose_covariance(exact_unit, R_wc, pairs[k].t,
                                                   pairs[k].covariance, predicted, false,
                                                   &exact_unit));
    }
    const double with_drift = analytic.topLeftCorner<3, 3>().trace();
    const double without = exact_unit.topLeftCorner<3, 3>().trace();
    EXPECT_GT(with_drift, 1.5 * without) << "seed " << seed;
  }
}

// With an exact unit and nothing handed on, the seventh state stays exact (the 6x6 chain, which
// propagate_pose_covariance is, matches Monte Carlo above); handed on, it takes the pair's relative
// length error.
TEST(PoseCovariance, TheUnitTakesOnlyWhatIsHandedOn) {
  std::mt19937_64 rng(8);
  const Matrix6d keyframe = random_covariance(rng, 1e-3, 1e-2);
  const Matrix6d pair = random_covariance(rng, 2e-3, 2e-2);
  const Eigen::Matrix3d R_wc = exp_so3(normal3(rng));
  const Eigen::Vector3d t = normal3(rng);
  // The filter keeps the chain's prediction.
  const Eigen::Matrix3d orientation =
      keyframe.bottomRightCorner<3, 3>() + R_wc * pair.topLeftCorner<3, 3>() * R_wc.transpose();
  Eigen::Matrix<double, 7, 7> scaled = Eigen::Matrix<double, 7, 7>::Zero(), out;
  scaled.topLeftCorner<6, 6>() = keyframe;
  ASSERT_TRUE(propagate_scaled_pose_covariance(scaled, R_wc, t, pair, orientation, false, &out));
  EXPECT_EQ(out.row(6).norm(), 0.0);
  // u^T C_t u / |t|^2, and the position's error along t goes with it: the position moves by
  // -R_wc dt - [R_wc t]x R_wc theta.
  ASSERT_TRUE(propagate_scaled_pose_covariance(scaled, R_wc, t, pair, orientation, true, &out));
  const Eigen::Vector3d u = t.normalized();
  EXPECT_NEAR(out(6, 6), u.dot(pair.bottomRightCorner<3, 3>() * u) / t.squaredNorm(),
              1e-12 * out(6, 6));
  Eigen::Matrix3d L;
  const Eigen::Vector3d Rt = R_wc * t;
  L << 0.0, -Rt.z(), Rt.y(), Rt.z(), 0.0, -Rt.x(), -Rt.y(), Rt.x(), 0.0;
  const Eigen::Vector3d cross = (-R_wc * pair.bottomRightCorner<3, 3>() -
                                 L * R_wc * pair.topRightCorner<3, 3>()) * u / t.norm();
  EXPECT_LT((out.block<3, 1>(0, 6) - cross).norm(), 1e-9 * cross.norm());
  // Not finite: refused, the output untouched.
  Eigen::Matrix<double, 7, 7> bad = scaled, kept = Eigen::Matrix<double, 7, 7>::Constant(2.0);
  bad(6, 6) = NAN;
  EXPECT_FALSE(propagate_scaled_pose_covariance(bad, R_wc, t, pair, orientation, true, &kept));
  EXPECT_EQ(kept, (Eigen::Matrix<double, 7, 7>::Constant(2.0)));
}

// The body's pose T_bc T_wc T_bc^-1 of perturbed camera poses.
TEST(PoseCovariance, BodyPoseMatchesMonteCarlo) {
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    std::mt19937_64 rng(seed);
    const Eigen::Matrix3d R_wc = exp_so3(normal3(rng)), R_bc = exp_so3(normal3(rng));
    const Eigen::Vector3d centre = normal3(rng, 3.0), t_bc = normal3(rng, 0.5);
    const Matrix6d camera = random_covariance(rng, 1e-2, 1e-3);
    auto body = [&](const Eigen::Matrix3d& R, const Eigen::Vector3d& c,
                    Eigen::Matrix3d* R_ob) -> Eigen::Vector3d {
      *R_ob = R_bc * R * R_bc.transpose();
      return R_bc * (R * (-R_bc.transpose() * t_bc) + c) + t_bc;
    };
    Eigen::Matrix3d R_ob;
    const Eigen::Vector3d p = body(R_wc, centre, &R_ob);
    const Sampler<6> error(camera);
    std::vector<Vector6d> errors;
    for (int s = 0; s < 20000; ++s) {
      const Vector6d e = error(rng);
      Eigen::Matrix3d R_ob_s;
      const Eigen::Vector3d p_s = body(exp_so3(e.tail<3>()) * R_wc, centre + e.head<3>(), &R_ob_s);
      Vector6d d;
      d << p_s - p, log_so3(R_ob_s * R_ob.transpose());
      errors.push_back(d);
    }
    const Matrix6d expected = body_pose_covariance(camera, R_wc, R_bc, t_bc);
    EXPECT_TRUE(is_covariance(expected));
    EXPECT_LT(relative_difference(sample_covariance(errors), expected), 0.04) << "seed " << seed;
  }
}

// The body's velocity over a pair, from the poses at both ends.
PairTwist twist_of_poses(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double dt,
                         const Eigen::Matrix3d& R_bc, const Eigen::Vector3d& t_bc) {
  Eigen::Isometry3d b_c = Eigen::Isometry3d::Identity();
  b_c.linear() = R_bc;
  b_c.translation() = t_bc;
  const Eigen::Isometry3d w_ref = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d cur_ref = Eigen::Isometry3d::Identity();  // X_cur = R X_ref + t
  cur_ref.linear() = R;
  cur_ref.translation() = t;
  const Eigen::Isometry3d w_cur = w_ref * cur_ref.inverse();
  const Eigen::Isometry3d o_b0 = b_c * w_ref * b_c.inverse(), o_b1 = b_c * w_cur * b_c.inverse();
  PairTwist twist;
  twist.linear = o_b1.rotation().transpose() * (o_b1.translation() - o_b0.translation()) / dt;
  twist.angular = log_so3(o_b0.rotation().transpose() * o_b1.rotation()) / dt;
  return twist;
}

TEST(PoseCovariance, PairTwistMatchesThePosesAndMonteCarlo) {
  // The camera itself: moving forward (z) and turning right (about y, down) in 0.1 s.
  const double dt = 0.1;
  const Eigen::Matrix3d yaw_right = exp_so3(Eigen::Vector3d(0, 0.05, 0));  // R_wc of the frame
  PairTwist twist;
  ASSERT_TRUE(pair_twist(yaw_right.transpose(), Eigen::Vector3d(0, 0, -1), Matrix6d::Zero(), dt,
                         Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), &twist));
  EXPECT_LT((twist.linear - Eigen::Vector3d(0, 0, 10)).norm(), 1e-12);
  EXPECT_LT((twist.angular - Eigen::Vector3d(0, 0.5, 0)).norm(), 1e-12);
  EXPECT_FALSE(pair_twist(yaw_right, Eigen::Vector3d::Zero(), Matrix6d::Zero(), 0.0,
                          Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), &twist));

  for (uint64_t seed = 1; seed <= 3; ++seed) {
    std::mt19937_64 rng(seed);
    const Eigen::Matrix3d R = exp_so3(normal3(rng, 0.3)), R_bc = exp_so3(normal3(rng));
    const Eigen::Vector3d t = normal3(rng), t_bc = normal3(rng, 0.5);
    const Matrix6d motion = random_covariance(rng, 1e-3, 1e-2);
    ASSERT_TRUE(pair_twist(R, t, motion, dt, R_bc, t_bc, &twist));
    const PairTwist truth = twist_of_poses(R, t, dt, R_bc, t_bc);
    EXPECT_LT((twist.linear - truth.linear).norm(), 1e-9);
    EXPECT_LT((twist.angular - truth.angular).norm(), 1e-9);
    EXPECT_TRUE(is_covariance(twist.covariance));
    const Sampler<6> error(motion);
    std::vector<Vector6d> errors;
    for (int s = 0; s < 20000; ++s) {
      const Vector6d e = error(rng);
      const PairTwist sampled =
          twist_of_poses(exp_so3(e.head<3>()) * R, t + e.tail<3>(), dt, R_bc, t_bc);
      Vector6d d;
      d << sampled.linear - truth.linear, sampled.angular - truth.angular;
      errors.push_back(d);
    }
    EXPECT_LT(relative_difference(sample_covariance(errors), twist.covariance), 0.04)
        << "seed " << seed;
  }
}

TEST(PoseCovariance, IsCovarianceRefusesAsymmetricIndefiniteAndNan) {
  Matrix6d C = Matrix6d::Identity();
  EXPECT_TRUE(is_covariance(C));
  EXPECT_TRUE(is_covariance(Matrix6d::Zero()));
  C(0, 1) = 0.5;
  EXPECT_FALSE(is_covariance(C));
  C(1, 0) = 0.5;
  EXPECT_TRUE(is_covariance(C));
  C(2, 2) = -0.1;
  EXPECT_FALSE(is_covariance(C));
  C(2, 2) = NAN;
  EXPECT_FALSE(is_covariance(C));
}

}  // namespace
}  // namespace hybrid_vo
