#include "hybrid_vo/direction_map/joint_orientation.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace hybrid_vo {
namespace {

void symmetrise(Eigen::MatrixXd* A) { *A = 0.5 * (*A + A->transpose()); }

}  // namespace

JointOrientation::JointOrientation(const Eigen::Matrix3d& P)
    : covariance_(Eigen::MatrixXd::Zero(kDirections, kDirections)) {
  covariance_.topLeftCorner<3, 3>() = 0.5 * (P + P.transpose());
}

void JointOrientation::predict(const Eigen::Matrix3d& Q, double direction_drift) {
  // The orientation moves with the pair, the directions stay: no cross-covariance changes.
  covariance_.topLeftCorner<3, 3>() += 0.5 * (Q + Q.transpose());
  if (direction_drift > 0.0)
    for (int r = kDirections; r < covariance_.rows(); ++r) covariance_(r, r) += direction_drift;
}

void JointOrientation::widen_orientation(const Eigen::Matrix3d& extra) {
  covariance_.topLeftCorner<3, 3>() += 0.5 * (extra + extra.transpose());
}

void JointOrientation::set_orientation(const Eigen::Matrix3d& P) {
  const Eigen::Matrix3d target = 0.5 * (P + P.transpose());
  const Eigen::Matrix3d old = covariance_.topLeftCorner<3, 3>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> growth(target - old,
                                                              Eigen::EigenvaluesOnly);
  const double tolerance = 1e-12 * std::max(1e-30, old.trace());
  if (growth.eigenvalues().minCoeff() >= -tolerance) {
    widen_orientation(target - old);
    return;
  }
  // [[P, a C], [a C^T, X]] stays positive semi-definite when a^2 C X^+ C^T <= P, which
  // a^2 lambda_max(old) <= lambda_min(P) guarantees (C X^+ C^T <= old).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> p(target, Eigen::EigenvaluesOnly);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> o(old, Eigen::EigenvaluesOnly);
  const double largest = o.eigenvalues().maxCoeff();
  const double a = largest > 0.0 ? std::min(1.0, std::sqrt(std::max(0.0, p.eigenvalues().minCoeff()) /
                                                             largest))
                                 : 0.0;
  const int n = static_cast<int>(covariance_.rows());
  covariance_.topRightCorner(3, n - 3) *= a;
  covariance_.bottomLeftCorner(n - 3, 3) *= a;
  covariance_.topLeftCorner<3, 3>() = target;
}

void JointOrientation::add_direction(const Eigen::Matrix<double, 2, 3>& J,
                                     const Eigen::Matrix2d& N) {
  const int n = static_cast<int>(covariance_.rows());
  Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(n + 2, n + 2);
  grown.topLeftCorner(n, n) = covariance_;
  // delta = J theta + noise: its covariance with every state is J times the orientation's row.
  const Eigen::MatrixXd cross = J * covariance_.topRows<3>();
  grown.block(n, 0, 2, n) = cross;
  grown.block(0, n, n, 2) = cross.transpose();
  grown.block<2, 2>(n, n) = J * covariance_.topLeftCorner<3, 3>() * J.transpose() + N;
  covariance_ = grown;
  symmetrise(&covariance_);
}

void JointOrientation::remove_direction(int j) {
  const int n = static_cast<int>(covariance_.rows());
  const int row = kDirections + 2 * j;
  if (j < 0 || row + 2 > n) return;
  Eigen::MatrixXd kept(n - 2, n - 2);
  const int after = n - row - 2;
  kept.topLeftCorner(row, row) = covariance_.topLeftCorner(row, row);
  kept.topRightCorner(row, after) = covariance_.topRightCorner(row, after);
  kept.bottomLeftCorner(after, row) = covariance_.bottomLeftCorner(after, row);
  kept.bottomRightCorner(after, after) = covariance_.bottomRightCorner(after, after);
  covariance_ = kept;
}

void JointOrientation::change_basis(int j, const Eigen::Matrix2d& T) {
  const int n = static_cast<int>(covariance_.rows());
  const int row = kDirections + 2 * j;
  if (j < 0 || row + 2 > n) return;
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(n, n);
  F.block<2, 2>(row, row) = T;
  covariance_ = F * covariance_ * F.transpose();
  symmetrise(&covariance_);
}

JointOrientation::Gain JointOrientation::gain(const Eigen::MatrixXd& H, const Eigen::MatrixXd& N,
                                              const std::vector<char>& estimated) const {
  Gain g;
  const int n = static_cast<int>(covariance_.rows());
  if (H.cols() != n || H.rows() != N.rows() || N.rows() != N.cols() ||
      static_cast<int>(estimated.size()) != n || H.rows() == 0)
    return g;
  const Eigen::MatrixXd PHt = covariance_ * H.transpose();
  const Eigen::MatrixXd S = H * PHt + N;
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(0.5 * (S + S.transpose()));
  if (!lu.isInvertible()) return g;
  g.S_inverse = lu.inverse();
  g.K = PHt * g.S_inverse;
  for (int i = 0; i < n; ++i)
    if (!estimated[i]) g.K.row(i).setZero();
  g.valid = g.K.allFinite() && g.S_inverse.allFinite();
  return g;
}

void JointOrientation::apply(const Gain& gain, const Eigen::MatrixXd& H, const Eigen::MatrixXd& N) {
  if (!gain.valid) return;
  const int n = static_cast<int>(covariance_.rows());
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n) - gain.K * H;
  covariance_ = A * covariance_ * A.transpose() + gain.K * N * gain.K.transpose();
  symmetrise(&covariance_);
}

}  // namespace hybrid_vo
