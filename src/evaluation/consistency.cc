#include "hybrid_vo/evaluation/consistency.h"

#include <algorithm>
#include <cstdio>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "hybrid_vo/evaluation/statistics.h"

namespace hybrid_vo {
namespace evaluation {
namespace {

// Rotation vector of R (log map).
Eigen::Vector3d rotation_log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// Two orthonormal vectors orthogonal to the unit vector d; the NEES does not depend on which.
Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& d) {
  int axis;
  d.cwiseAbs().minCoeff(&axis);
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = d.cross(Eigen::Vector3d::Unit(axis)).normalized();
  B.col(1) = d.cross(B.col(0));
  return B;
}

template <int N>
double nees(const Eigen::Matrix<double, N, 1>& error,
            const Eigen::Matrix<double, N, N>& covariance) {
  return error.dot(covariance.llt().solve(error));
}

}  // namespace

double chi_square_95(int dof) {
  static const double kQuantile[] = {3.8415, 5.9915, 7.8147};
  return dof >= 1 && dof <= 3 ? kQuantile[dof - 1] : NAN;
}

double chi_square_median(int dof) {
  static const double kMedian[] = {0.4549, 1.3863, 2.3660};
  return dof >= 1 && dof <= 3 ? kMedian[dof - 1] : NAN;
}

bool usable_covariance(const Eigen::MatrixXd& covariance, int rank) {
  const Eigen::Index n = covariance.rows();
  if (n == 0 || covariance.cols() != n || rank < 1 || rank > n || !covariance.allFinite())
    return false;
  const double largest = covariance.cwiseAbs().maxCoeff();
  if (!(largest > 0.0)) return false;
  if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() > 1e-9 * largest) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      0.5 * (covariance + covariance.transpose()), Eigen::EigenvaluesOnly);
  if (solver.info() != Eigen::Success) return false;
  const Eigen::VectorXd& eigenvalues = solver.eigenvalues();  // ascending
  const double top = eigenvalues(n - 1);
  return top > 0.0 && eigenvalues(0) >= -1e-9 * top && eigenvalues(n - rank) > 1e-12 * top;
}

Eigen::Matrix3d covariance_block(const double* row_major_6x6, int first) {
  Eigen::Matrix3d block;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) block(r, c) = row_major_6x6[(first + r) * 6 + first + c];
  return block;
}

double rotation_nees(const Eigen::Matrix3d& R_est, const Eigen::Matrix3d& R_true,
                     const Eigen::Matrix3d& covariance, double truth_sigma) {
  if (!usable_covariance(covariance, 3) || !R_est.allFinite() || !R_true.allFinite()) return NAN;
  const Eigen::Vector3d w = rotation_log(R_est * R_true.transpose());
  const Eigen::Matrix3d C =
      covariance + truth_sigma * truth_sigma * Eigen::Matrix3d::Identity();
  return nees<3>(w, C);
}

double direction_nees(const Eigen::Vector3d& t_est, const Eigen::Vector3d& t_true,
                      const Eigen::Matrix3d& covariance, double truth_sigma) {
  const double length = t_est.norm();
  if (!(length > 0.0) || !(t_true.norm() > 0.0) || !std::isfinite(length) ||
      !t_true.allFinite() || !usable_covariance(covariance, 2))
    return NAN;
  const Eigen::Vector3d d_est = t_est / length, d_true = t_true.normalized();
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(d_est);
  const Eigen::Matrix2d projected = B.transpose() * covariance * B / (length * length);
  if (!usable_covariance(projected, 2)) return NAN;
  // The sphere's log map at d_est: B^T d_true has length sin(angle).
  const double sine = d_est.cross(d_true).norm(), angle = std::atan2(sine, d_est.dot(d_true));
  const Eigen::Vector2d offset = B.transpose() * (d_est - d_true);
  if (sine < 1e-12 && angle > 0.5 * M_PI) return std::numeric_limits<double>::infinity();
  const Eigen::Vector2d e = sine < 1e-12 ? offset : Eigen::Vector2d(angle / sine * offset);
  const Eigen::Matrix2d C = projected + truth_sigma * truth_sigma * Eigen::Matrix2d::Identity();
  return nees<2>(e, C);
}

double direction_pair_nees(const Eigen::Vector3d& d_a, const Eigen::Matrix3d& C_a,
                           const Eigen::Vector3d& d_b, const Eigen::Matrix3d& C_b,
                           const Eigen::Matrix3d& R_ba) {
  if (!(d_a.norm() > 0.0) || !(d_b.norm() > 0.0) || !d_a.allFinite() || !d_b.allFinite() ||
      !C_a.allFinite() || !C_b.allFinite() || !R_ba.allFinite())
    return NAN;
  Eigen::Vector3d carried = (R_ba * d_a).normalized();
  const Eigen::Vector3d b = d_b.normalized();
  if (carried.dot(b) < 0.0) carried = -carried;
  // Both errors in b's tangent plane: a's covariance turns with it (the sign does not matter).
  return direction_nees(b, carried, C_b + R_ba * C_a * R_ba.transpose());
}

void DirectionSightings::add(int frame, int id, const Eigen::Vector3d& d, const Eigen::Matrix3d& C,
                             const Eigen::Matrix3d& R_true) {
  const auto last = last_.find(id);
  if (last != last_.end()) {
    if (frame - last->second.frame < min_gap_) return;
    nees_.push_back(direction_pair_nees(last->second.d, last->second.C, d, C,
                                        R_true.transpose() * last->second.R_true));
  }
  last_[id] = {frame, d, C, R_true};
}

double translation_nees(const Eigen::Vector3d& t_est, const Eigen::Vector3d& t_true,
                        const Eigen::Matrix3d& covariance, double truth_sigma) {
  if (!t_est.allFinite() || !t_true.allFinite() || !usable_covariance(covariance, 3)) return NAN;
  return nees<3>(Eigen::Vector3d(t_est - t_true),
                 covariance + truth_sigma * truth_sigma * Eigen::Matrix3d::Identity());
}

RelativeOrientation relative_orientation(const Eigen::Matrix3d& R0_est,
                                         const Eigen::Matrix3d& Rk_est,
                                         const Eigen::Matrix3d& R0_true,
                                         const Eigen::Matrix3d& Rk_true,
                                         const Eigen::Matrix3d& covariance_world) {
  // R_k_est = exp([w]x) R_k gives R_rel_est = exp([R_0^T w]x) R_rel: the increment seen from
  // the first camera.
  RelativeOrientation o;
  const Eigen::Matrix3d est = R0_est.transpose() * Rk_est, truth = R0_true.transpose() * Rk_true;
  o.error = rotation_log(est * truth.transpose());
  o.covariance = R0_est.transpose() * covariance_world * R0_est;
  return o;
}

double orientation_nees(const Eigen::Matrix3d& R0_est, const Eigen::Matrix3d& Rk_est,
                        const Eigen::Matrix3d& R0_true, const Eigen::Matrix3d& Rk_true,
                        const Eigen::Matrix3d& covariance_world, double truth_sigma) {
  if (!usable_covariance(covariance_world, 3) || !R0_est.allFinite() || !Rk_est.allFinite() ||
      !R0_true.allFinite() || !Rk_true.allFinite())
    return NAN;
  const RelativeOrientation o =
      relative_orientation(R0_est, Rk_est, R0_true, Rk_true, covariance_world);
  return nees<3>(o.error,
                 Eigen::Matrix3d(o.covariance + truth_sigma * truth_sigma *
                                                    Eigen::Matrix3d::Identity()));
}

NeesSummary summarize_nees(const std::vector<double>& nees, int dof) {
  NeesSummary s;
  s.dof = dof;
  s.count = static_cast<int>(nees.size());
  std::vector<double> valid;
  for (double v : nees)
    if (std::isnan(v)) ++s.missing;
    else valid.push_back(v);
  if (valid.empty()) return s;
  s.median = median(valid);
  s.p90 = percentile(valid, 0.9);
  const double bound = chi_square_95(dof);
  s.inside95 = static_cast<double>(std::count_if(valid.begin(), valid.end(),
                                                 [&](double v) { return v <= bound; })) /
               valid.size();
  return s;
}

std::string describe_nees(const NeesSummary& s, const std::string& what) {
  char text[256];
  const int with = s.count - s.missing;
  if (with == 0)
    std::snprintf(text, sizeof(text), "NEES: none of %d %s with a covariance", s.count,
                  what.c_str());
  else
    std::snprintf(text, sizeof(text),
                  "NEES median %.2f (honest %.3f), p90 %.2f, %.1f %% inside the 95 %% ellipsoid "
                  "(%.3f); %d of %d %s with a covariance",
                  s.median, chi_square_median(s.dof), s.p90, 100.0 * s.inside95,
                  chi_square_95(s.dof), with, s.count, what.c_str());
  return text;
}

}  // namespace evaluation
}  // namespace hybrid_vo
