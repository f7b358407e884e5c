#include "hybrid_vo/estimation/pair_covariance.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {
namespace {

// Inverse of a symmetric positive semi-definite matrix restricted to its range (eigenvalues
// below `relative` of the largest are treated as zero).
Eigen::MatrixXd pseudo_inverse(const Eigen::MatrixXd& A, double relative = 1e-12) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (A + A.transpose()));
  Eigen::VectorXd inverse = eigen.eigenvalues();
  const double largest = std::max(0.0, inverse.size() ? inverse.maxCoeff() : 0.0);
  for (int k = 0; k < inverse.size(); ++k)
    inverse(k) = inverse(k) > relative * largest && inverse(k) > 0.0 ? 1.0 / inverse(k) : 0.0;
  return eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
}

}  // namespace

Eigen::Matrix3d rotation_spread(const std::vector<PoseHypothesis>& hypotheses,
                                const Eigen::Matrix3d& R, double best_cost, double temperature) {
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  if (!(temperature > 0.0) || !std::isfinite(best_cost) || !all_finite(R)) return spread;
  double total = 1.0;  // R itself
  for (const PoseHypothesis& h : hypotheses) {
    if (!all_finite(h.R) || !std::isfinite(h.cost)) continue;
    const double weight = std::exp(-std::max(0.0, h.cost - best_cost) / temperature);
    const Eigen::AngleAxisd apart(Eigen::Matrix3d(h.R * R.transpose()));
    const Eigen::Vector3d w = apart.angle() * apart.axis();
    if (!all_finite(w)) continue;
    spread += weight * w * w.transpose();
    total += weight;
  }
  return spread / total;
}

Eigen::Matrix<double, 5, 5> pose_spread(const std::vector<PoseHypothesis>& hypotheses,
                                        const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                        const Eigen::Matrix<double, 3, 2>& B, double best_cost,
                                        double temperature) {
  Eigen::Matrix<double, 5, 5> spread = Eigen::Matrix<double, 5, 5>::Zero();
  const double length = t.norm();
  if (!(temperature > 0.0) || !std::isfinite(best_cost) || !all_finite(R) || !all_finite(B) ||
      !(length > 0.0) || !std::isfinite(length))
    return spread;
  const Eigen::Vector3d u = t / length;
  double total = 1.0;  // (R, t) itself
  for (const PoseHypothesis& h : hypotheses) {
    if (!all_finite(h.R) || !std::isfinite(h.cost) || !all_finite(h.t)) continue;
    const double weight = std::exp(-std::max(0.0, h.cost - best_cost) / temperature);
    const Eigen::AngleAxisd apart(Eigen::Matrix3d(h.R * R.transpose()));
    Eigen::Matrix<double, 5, 1> z = Eigen::Matrix<double, 5, 1>::Zero();
    z.head<3>() = apart.angle() * apart.axis();
    if (h.t.norm() > 0.0) {
      // The sphere's log map at u of the nearer sign of h.t: its angle along the tangent.
      const Eigen::Vector3d v = (h.t.dot(u) < 0.0 ? -h.t : h.t).normalized();
      const Eigen::Vector3d across = v - v.dot(u) * u;
      const double sine = across.norm(), angle = std::atan2(sine, v.dot(u));
      if (sine > 1e-15) z.tail<2>() = B.transpose() * across * (angle / sine);
    }
    if (!all_finite(z)) continue;
    spread += weight * z * z.transpose();
    total += weight;
  }
  return spread / total;
}

double hypothesis_temperature(double matches, double independent, double sigma_px,
                              double threshold_px) {
  if (!(threshold_px > 0.0) || !(sigma_px > 0.0) || !(independent > 0.0)) return 0.0;
  const double ratio = sigma_px / threshold_px;
  return 2.0 * ratio * ratio * std::max(1.0, matches / independent);
}

bool pair_covariance(const InformationSplit& split, const Eigen::Matrix<double, 5, 5>& spread,
                     double point_matches, double segments, const PairCovarianceOptions& options,
                     Eigen::Matrix<double, 6, 6>* covariance) {
  covariance->setZero();
  if (!split.valid || !all_finite(spread)) return false;
  const int n = static_cast<int>(split.segment_information.rows());
  if (n < 5 || split.prior_information.rows() != n) return false;
  const double g_points = std::max(1.0, point_matches / options.independent_points);
  const double g_segments = std::max(1.0, segments / options.independent_segments);
  // The points' own covariance, widened by the competing poses; as information.
  Eigen::Matrix<double, 5, 5> points = g_points * split.points_covariance + spread;
  const Eigen::LLT<Eigen::Matrix<double, 5, 5>> llt(0.5 * (points + points.transpose()));
  if (llt.info() != Eigen::Success) return false;
  // Segments, VPs and priors, their VP directions marginalised (Schur complement).
  const Eigen::MatrixXd other = split.segment_information / g_segments + split.prior_information;
  Eigen::Matrix<double, 5, 5> information = llt.solve(Eigen::Matrix<double, 5, 5>::Identity());
  information += other.topLeftCorner<5, 5>();
  if (n > 5) {
    const Eigen::MatrixXd B = other.topRightCorner(5, n - 5);
    information -= B * pseudo_inverse(other.bottomRightCorner(n - 5, n - 5)) * B.transpose();
  }
  const Eigen::LLT<Eigen::Matrix<double, 5, 5>> posterior(0.5 * (information +
                                                                 information.transpose()));
  if (posterior.info() != Eigen::Success) return false;
  const Eigen::Matrix<double, 5, 5> tangent =
      posterior.solve(Eigen::Matrix<double, 5, 5>::Identity());
  const Eigen::Matrix<double, 6, 6> full = split.to_pose * tangent * split.to_pose.transpose();
  if (!all_finite(full)) return false;
  *covariance = 0.5 * (full + full.transpose());
  return true;
}

}  // namespace hybrid_vo
