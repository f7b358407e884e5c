#include "hybrid_vo/estimation/refine_relative_pose.h"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

using Vector5d = Eigen::Matrix<double, 5, 1>;
using Matrix5d = Eigen::Matrix<double, 5, 5>;

// Two unit vectors spanning the tangent plane of the sphere at unit t.
Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& t) {
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = t.unitOrthogonal();
  B.col(1) = t.cross(B.col(0));
  return B;
}

RelativePose apply_step(const RelativePose& pose, const Vector5d& step) {
  RelativePose updated;
  const double angle = step.head<3>().norm();
  updated.R = angle > 0.0 ? Eigen::Matrix3d(rotation_about(step.head<3>() / angle, angle) * pose.R)
                          : pose.R;
  updated.t = (pose.t + tangent_basis(pose.t) * step.tail<2>()).normalized();
  return updated;
}

double robust_weight(double squared_residual, double scale) {
  if (scale <= 0.0) return 1.0;
  return 1.0 / (1.0 + squared_residual / (scale * scale));  // Cauchy (IRLS)
}

double robust_cost(double squared_residual, double scale) {
  if (scale <= 0.0) return squared_residual;
  return scale * scale * std::log1p(squared_residual / (scale * scale));
}

// Accumulates the normal equations (and cost) of all residuals at `pose`.
double accumulate(const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2,
                  const std::vector<Eigen::Vector3d>& v1, const std::vector<Eigen::Vector3d>& v2,
                  const RelativePoseRefinementOptions& options, const RelativePose& pose,
                  Matrix5d* JtJ, Vector5d* Jtr) {
  if (JtJ) JtJ->setZero();
  if (Jtr) Jtr->setZero();
  const Eigen::Matrix3d E = pose.essential();
  const Eigen::Matrix<double, 3, 2> B = tangent_basis(pose.t);
  // dE for the five parameters: [t]x [e_k]x R (rotation) and [b_j]x R (translation).
  Eigen::Matrix3d dE[5];
  const Eigen::Matrix3d tx = skew(pose.t);
  for (int k = 0; k < 3; ++k) dE[k] = tx * skew(Eigen::Vector3d::Unit(k)) * pose.R;
  for (int j = 0; j < 2; ++j) dE[3 + j] = skew(B.col(j)) * pose.R;

  double cost = 0.0;
  for (size_t i = 0; i < x1.size(); ++i) {
    const Eigen::Vector3d p = homogeneous(x1[i]), q = homogeneous(x2[i]);
    const Eigen::Vector3d Ep = E * p, Etq = E.transpose() * q;
    const double C = q.dot(Ep);
    const double D = Ep.head<2>().squaredNorm() + Etq.head<2>().squaredNorm();
    if (!(D > 0.0)) continue;
    const double r = C / std::sqrt(D);
    const double w = robust_weight(r * r, options.loss_scale);
    cost += robust_cost(r * r, options.loss_scale);
    if (!JtJ) continue;
    Vector5d J;
    for (int k = 0; k < 5; ++k) {
      const Eigen::Vector3d dEp = dE[k] * p, dEtq = dE[k].transpose() * q;
      const double dC = q.dot(dEp);
      const double dD = 2.0 * (Ep.head<2>().dot(dEp.head<2>()) + Etq.head<2>().dot(dEtq.head<2>()));
      J(k) = dC / std::sqrt(D) - 0.5 * C * dD / (D * std::sqrt(D));
    }
    *JtJ += w * J * J.transpose();
    *Jtr += w * J * r;
  }
  for (size_t i = 0; i < v1.size(); ++i) {
    const Eigen::Vector3d a = v1[i].normalized(), b = v2[i].normalized();
    const Eigen::Vector3d Ra = pose.R * a;
    // Known sign: R a - b. Unknown: b x R a, whose norm is |sin| of the angle either way.
    const Eigen::Vector3d r = options.vp_weight * (options.vp_signs_known ? Eigen::Vector3d(Ra - b)
                                                                          : Eigen::Vector3d(b.cross(Ra)));
    const double w = robust_weight(r.squaredNorm(), options.loss_scale);
    cost += robust_cost(r.squaredNorm(), options.loss_scale);
    if (!JtJ) continue;
    // d(R a)/dw = -[R a]x for the left increment; translation does not enter.
    Eigen::Matrix<double, 3, 5> J = Eigen::Matrix<double, 3, 5>::Zero();
    const Eigen::Matrix3d dRa = -skew(Ra);
    J.leftCols<3>() = options.vp_weight * (options.vp_signs_known ? dRa : Eigen::Matrix3d(skew(b) * dRa));
    *JtJ += w * J.transpose() * J;
    *Jtr += w * J.transpose() * r;
  }
  return cost;
}

}  // namespace

double sampson_error(const Eigen::Matrix3d& E, const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  const Eigen::Vector3d p = homogeneous(x1), q = homogeneous(x2);
  const Eigen::Vector3d Ep = E * p, Etq = E.transpose() * q;
  const double D = Ep.head<2>().squaredNorm() + Etq.head<2>().squaredNorm();
  if (!(D > 0.0)) return std::abs(q.dot(Ep)) > 0.0 ? INFINITY : 0.0;
  return std::abs(q.dot(Ep)) / std::sqrt(D);
}

RelativePoseRefinementSummary refine_relative_pose(
    const std::vector<Eigen::Vector2d>& x1, const std::vector<Eigen::Vector2d>& x2,
    const std::vector<Eigen::Vector3d>& v1, const std::vector<Eigen::Vector3d>& v2,
    const RelativePoseRefinementOptions& options, RelativePose* pose) {
  RelativePoseRefinementSummary summary;
  const size_t rows = x1.size() + 3 * v1.size();
  if (x1.size() != x2.size() || v1.size() != v2.size() || rows < 5) return summary;
  if (!(pose->t.norm() > 0.0) || !all_finite(pose->R) || !all_finite(pose->t)) return summary;
  for (size_t i = 0; i < x1.size(); ++i)
    if (!all_finite(x1[i]) || !all_finite(x2[i])) return summary;
  for (size_t i = 0; i < v1.size(); ++i)
    if (!all_finite(v1[i]) || !all_finite(v2[i])) return summary;
  pose->t.normalize();

  Matrix5d JtJ;
  Vector5d Jtr;
  double cost = accumulate(x1, x2, v1, v2, options, *pose, &JtJ, &Jtr);
  summary.initial_cost = cost;
  double lambda = 1e-4;
  for (int iter = 0; iter < options.max_iterations; ++iter) {
    summary.iterations = iter + 1;
    Matrix5d A = JtJ;
    A.diagonal() += lambda * JtJ.diagonal().cwiseMax(1e-12);
    const Vector5d step = A.ldlt().solve(-Jtr);
    if (!all_finite(step)) break;
    const RelativePose candidate = apply_step(*pose, step);
    const double candidate_cost = accumulate(x1, x2, v1, v2, options, candidate, nullptr, nullptr);
    if (candidate_cost < cost) {
      const double decrease = (cost - candidate_cost) / std::max(cost, 1e-300);
      *pose = candidate;
      cost = accumulate(x1, x2, v1, v2, options, *pose, &JtJ, &Jtr);
      lambda = std::max(1e-10, lambda / 10.0);
      if (decrease < options.function_tolerance) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e10) break;
    }
  }
  summary.final_cost = cost;
  return summary;
}

}  // namespace hybrid_vo
