#include "hybrid_vo/geometry/vp_covariance.h"

#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "hybrid_vo/geometry/vp_distance.h"

namespace hybrid_vo {

Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& d) {
  // Start from the axis least aligned with d, so the cross product is well conditioned.
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  int smallest = 0;
  d.cwiseAbs().minCoeff(&smallest);
  axis[smallest] = 1.0;
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = d.cross(axis).normalized();
  B.col(1) = d.cross(B.col(0)).normalized();
  return B;
}

bool vp_measurement_covariance(const Eigen::Matrix3d& K, const std::vector<LineSegment>& segments,
                               const Eigen::Vector3d& direction, double sigma_px,
                               double vp_sigma_rad, Eigen::Matrix3d* covariance) {
  const Eigen::Vector3d d = direction.normalized();
  *covariance = vp_sigma_rad * vp_sigma_rad * (Eigen::Matrix3d::Identity() - d * d.transpose());
  Eigen::Matrix3d fit;
  if (!vp_direction_covariance(K, segments, direction, sigma_px, &fit)) return false;
  *covariance += fit;
  return true;
}

bool vp_direction_covariance(const Eigen::Matrix3d& K, const std::vector<LineSegment>& segments,
                             const Eigen::Vector3d& direction, double sigma_px,
                             Eigen::Matrix3d* covariance) {
  if (!all_finite(K) || !all_finite(direction) || !(direction.norm() > 0.0) ||
      !(sigma_px > 0.0) || !std::isfinite(sigma_px))
    return false;
  const Eigen::Vector3d d = direction.normalized();
  const Eigen::Vector3d v = K * d;
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(d);
  const Eigen::Matrix<double, 3, 2> KB = K * B;
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
  int used = 0;
  for (const LineSegment& s : segments) {
    if (!all_finite(s.p1) || !all_finite(s.p2) || !(s.length() > 0.0)) continue;
    double r;
    Eigen::Vector3d dr_dv;
    if (!tardif_distance(s.line(), s.midpoint(), v, &r, &dr_dv) || !all_finite(dr_dv)) continue;
    const Eigen::RowVector2d J = dr_dv.transpose() * KB;  // per unit tangent step of d
    information += J.transpose() * J;
    ++used;
  }
  if (used < 2) return false;
  information /= sigma_px * sigma_px;
  // Both tangent directions must be constrained: reciprocal condition number above 1e-12.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(information);
  if (eigen.info() != Eigen::Success ||
      !(eigen.eigenvalues()(0) > 1e-12 * eigen.eigenvalues()(1)))
    return false;
  const Eigen::Matrix3d result = B * information.inverse() * B.transpose();
  if (!all_finite(result)) return false;
  *covariance = result;
  return true;
}

double direction_chi2(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      const Eigen::Matrix3d& covariance, bool signed_match) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (!all_finite(a) || !all_finite(b) || !all_finite(covariance) || !(a.norm() > 0.0) ||
      !(b.norm() > 0.0))
    return kInfinity;
  const Eigen::Vector3d u = a.normalized();
  Eigen::Vector3d w = b.normalized();
  const double c = u.dot(w);
  if (!signed_match && c < 0.0) w = -w;
  if (!(u.dot(w) > 0.0)) return kInfinity;  // more than 90 degrees apart
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(u);
  // Gnomonic coordinates of w around u: tan of the angle, the angle itself to first order.
  const Eigen::Vector2d y = B.transpose() * w / u.dot(w);
  const Eigen::Matrix2d S = B.transpose() * covariance * B;
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(S);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return kInfinity;
  const double chi2 = y.dot(ldlt.solve(y));
  return std::isfinite(chi2) ? chi2 : kInfinity;
}

}  // namespace hybrid_vo
