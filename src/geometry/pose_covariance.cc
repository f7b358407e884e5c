#include "hybrid_vo/geometry/pose_covariance.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace hybrid_vo {
namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

template <int N>
Eigen::Matrix<double, N, N> symmetric(const Eigen::Matrix<double, N, N>& A) {
  return 0.5 * (A + A.transpose());
}

// Negative eigenvalues of round-off set to zero.
Eigen::Matrix3d clip_psd(const Eigen::Matrix3d& A) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e(symmetric<3>(A));
  return e.eigenvectors() * e.eigenvalues().cwiseMax(0.0).asDiagonal() *
         e.eigenvectors().transpose();
}

// The filter's step from the chain's predicted orientation covariance P to its own Pf, as a
// linear model of the errors: delta_f = M delta_p + w, with w independent of all before and of
// covariance W = Pf - M P M^T >= 0. In P's whitened frame, S = P^-1/2 Pf P^-1/2 = U diag(l) U^T,
// M = P^1/2 U diag(min(l, 1)) U^T P^-1/2. Where the filter shrank P (the map's correction, a
// measurement of the orientation alone) M is the Kalman update's I - K, which shrinks the
// position-rotation terms with it; where it grew P (drift floor, blank wall) M = I and w is
// noise the position has not seen. Either way the joint covariance stays positive semi-definite.
void filter_step(const Eigen::Matrix3d& P, const Eigen::Matrix3d& Pf, Eigen::Matrix3d* M,
                 Eigen::Matrix3d* W) {
  // A ridge far below both keeps P invertible; P = Pf = 0 gives M = 0, W = 0.
  const double ridge = 1e-12 * (std::abs(P.trace()) + std::abs(Pf.trace())) + 1e-300;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> p(symmetric<3>(P));
  const Eigen::Vector3d root = (p.eigenvalues().cwiseMax(0.0).array() + ridge).sqrt();
  const Eigen::Matrix3d& V = p.eigenvectors();
  const Eigen::Matrix3d P_half = V * root.asDiagonal() * V.transpose();
  const Eigen::Matrix3d P_inv_half = V * root.cwiseInverse().asDiagonal() * V.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> s(
      symmetric<3>(P_inv_half * Pf * P_inv_half));
  const Eigen::Vector3d shrink = s.eigenvalues().cwiseMax(0.0).cwiseMin(1.0);
  *M = P_half * s.eigenvectors() * shrink.asDiagonal() * s.eigenvectors().transpose() * P_inv_half;
  *W = clip_psd(Pf - *M * P * M->transpose());
}

// The inverse of SO(3)'s left Jacobian at the rotation vector phi: how Log(Exp(d) R) moves with a
// small left increment d.
Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  const double c = angle < 1e-4 ? 1.0 / 12.0
                                : 1.0 / (angle * angle) -
                                      (1.0 + std::cos(angle)) / (2.0 * angle * std::sin(angle));
  return Eigen::Matrix3d::Identity() - 0.5 * K + c * K * K;
}

}  // namespace

bool propagate_scaled_pose_covariance(const Matrix7d& keyframe, const Eigen::Matrix3d& R_wc,
                                      const Eigen::Vector3d& t, const Matrix6d& motion_covariance,
                                      const Eigen::Matrix3d& orientation_covariance,
                                      bool hands_on, Matrix7d* out) {
  if (!keyframe.allFinite() || !R_wc.allFinite() || !t.allFinite() ||
      !motion_covariance.allFinite() || !orientation_covariance.allFinite())
    return false;
  // The errors: the keyframe's (position c, rotation phi, log-scale s), the pair's (theta, dt)
  // and the filter's own w. The chain predicts phi_p = phi - R_wc theta; the filter holds
  // phi' = M phi_p + w; centre = c - R_wc t e^s moves by [R_wc t]x phi' - R_wc dt - R_wc t s; a
  // pair that hands the unit on leaves s' = s + u^T dt / |t| (u = t / |t|), else s' = s.
  const Eigen::Matrix3d predicted = keyframe.block<3, 3>(3, 3) +
                                    R_wc * motion_covariance.topLeftCorner<3, 3>() *
                                        R_wc.transpose();
  Eigen::Matrix3d M, W;
  filter_step(predicted, orientation_covariance, &M, &W);
  const Eigen::Matrix3d L = skew(R_wc * t);
  // Columns: c (0), phi (3), s (6), theta (7), dt (10), w (13).
  Eigen::Matrix<double, 7, 16> J = Eigen::Matrix<double, 7, 16>::Zero();
  J.block<3, 3>(0, 0).setIdentity();
  J.block<3, 3>(0, 3) = L * M;
  J.block<3, 1>(0, 6) = -R_wc * t;
  J.block<3, 3>(0, 7) = -L * M * R_wc;
  J.block<3, 3>(0, 10) = -R_wc;
  J.block<3, 3>(0, 13) = L;
  J.block<3, 3>(3, 3) = M;
  J.block<3, 3>(3, 7) = -M * R_wc;
  J.block<3, 3>(3, 13).setIdentity();
  J(6, 6) = 1.0;
  const double length = t.norm();
  if (hands_on && length > 0.0) J.block<1, 3>(6, 10) = t.transpose() / (length * length);
  Eigen::Matrix<double, 16, 16> Z = Eigen::Matrix<double, 16, 16>::Zero();
  Z.block<7, 7>(0, 0) = keyframe;
  Z.block<6, 6>(7, 7) = motion_covariance;
  Z.block<3, 3>(13, 13) = W;
  const Matrix7d result = symmetric<7>(J * Z * J.transpose());
  if (!result.allFinite()) return false;
  *out = result;
  return true;
}

bool propagate_pose_covariance(const Matrix6d& keyframe, const Eigen::Matrix3d& R_wc,
                               const Eigen::Vector3d& t, const Matrix6d& motion_covariance,
                               const Eigen::Matrix3d& orientation_covariance, Matrix6d* out) {
  Matrix7d scaled = Matrix7d::Zero(), result;
  scaled.topLeftCorner<6, 6>() = keyframe;
  if (!propagate_scaled_pose_covariance(scaled, R_wc, t, motion_covariance,
                                        orientation_covariance, false, &result))
    return false;
  *out = result.topLeftCorner<6, 6>();
  return true;
}

void PoseCovarianceChain::integrate(const Matrix7d& keyframe, const Eigen::Matrix3d& R_wc,
                                    const Eigen::Vector3d& t, const Matrix6d* motion_covariance,
                                    const Eigen::Matrix3d& orientation_covariance,
                                    bool hands_on) {
  if (!motion_covariance) ++gaps_;
  const Matrix6d pair = motion_covariance ? *motion_covariance : Matrix6d::Zero();
  if (propagate_scaled_pose_covariance(keyframe, R_wc, t, pair, orientation_covariance,
                                       hands_on && motion_covariance, &covariance_))
    return;
  if (motion_covariance) ++gaps_;  // the last covariance stays
}

void PoseCovarianceChain::integrate(const Matrix6d& keyframe, const Eigen::Matrix3d& R_wc,
                                    const Eigen::Vector3d& t, const Matrix6d* motion_covariance,
                                    const Eigen::Matrix3d& orientation_covariance) {
  Matrix7d scaled = Matrix7d::Zero();
  scaled.topLeftCorner<6, 6>() = keyframe;
  integrate(scaled, R_wc, t, motion_covariance, orientation_covariance, false);
}

Matrix6d body_pose_covariance(const Matrix6d& camera, const Eigen::Matrix3d& R_wc,
                              const Eigen::Matrix3d& R_bc, const Eigen::Vector3d& t_bc) {
  // The body's origin sits at b in the camera, R_wc b + centre in the first camera's frame: the
  // camera's rotation error swings it about the camera.
  const Eigen::Vector3d b = -R_bc.transpose() * t_bc;
  Matrix6d J = Matrix6d::Zero();
  J.block<3, 3>(0, 0) = R_bc;
  J.block<3, 3>(0, 3) = -R_bc * skew(R_wc * b);
  J.block<3, 3>(3, 3) = R_bc;
  return symmetric<6>(J * camera * J.transpose());
}

bool pair_twist(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                const Matrix6d& motion_covariance, double dt, const Eigen::Matrix3d& R_bc,
                const Eigen::Vector3d& t_bc, PairTwist* out) {
  if (!(dt > 0.0) || !std::isfinite(dt) || !R.allFinite() || !t.allFinite() ||
      !motion_covariance.allFinite() || !R_bc.allFinite() || !t_bc.allFinite())
    return false;
  // The body's origin b in the camera moved by (I - R) b - t in the current camera, and the
  // body turned by R^T: angular velocity -Log(R) / dt.
  const Eigen::Vector3d b = -R_bc.transpose() * t_bc;
  const Eigen::AngleAxisd turned(R);
  const Eigen::Vector3d phi = turned.angle() * turned.axis();
  PairTwist twist;
  twist.linear = R_bc * ((b - R * b) - t) / dt;
  twist.angular = -R_bc * phi / dt;
  Matrix6d J = Matrix6d::Zero();  // of [linear, angular] by [theta, t]
  J.block<3, 3>(0, 0) = R_bc * skew(R * b) / dt;
  J.block<3, 3>(0, 3) = -R_bc / dt;
  J.block<3, 3>(3, 0) = -R_bc * left_jacobian_inverse(phi) / dt;
  twist.covariance = symmetric<6>(J * motion_covariance * J.transpose());
  if (!twist.linear.allFinite() || !twist.angular.allFinite() || !twist.covariance.allFinite())
    return false;
  *out = twist;
  return true;
}

bool is_covariance(const Matrix6d& C) {
  if (!C.allFinite()) return false;
  const double scale = C.cwiseAbs().maxCoeff();
  if ((C - C.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) return false;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> e(symmetric<6>(C));
  return e.eigenvalues().minCoeff() >= -1e-9 * scale;
}

}  // namespace hybrid_vo
