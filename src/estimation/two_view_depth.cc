#include "hybrid_vo/estimation/two_view_depth.h"

#include <cmath>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

InverseDepth triangulate_inverse_depth(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                       const Eigen::Vector2d& x1, const Eigen::Vector2d& x2,
                                       double sigma_n) {
  InverseDepth out;
  if (!all_finite(R) || !all_finite(t) || !all_finite(x1) || !all_finite(x2) ||
      !(sigma_n > 0.0) || !(t.norm() > 0.0))
    return out;
  // X1 = R^T (X2 - t), and X2 = [x2; 1] / rho: rho X1 = a - rho b.
  const Eigen::Vector3d a = R.transpose() * homogeneous(x2), b = R.transpose() * t;
  const Eigen::Vector3d x = homogeneous(x1);
  const Eigen::Vector3d xb = x.cross(b);
  const double xb2 = xb.squaredNorm();
  if (!(xb2 > 1e-24)) return out;
  double rho = x.cross(a).dot(xb) / xb2;  // x1 x (a - rho b) = 0 in least squares
  // Where the projection moves with rho the noise of both images counts, each image once.
  Eigen::Vector2d J = Eigen::Vector2d::Zero();
  for (int iteration = 0; iteration < 5; ++iteration) {
    const Eigen::Vector3d P = a - rho * b;
    if (!(P.z() > 0.0)) return out;
    const Eigen::Vector2d r(P.x() / P.z() - x1.x(), P.y() / P.z() - x1.y());
    J = Eigen::Vector2d((-b.x() * P.z() + b.z() * P.x()) / (P.z() * P.z()),
                        (-b.y() * P.z() + b.z() * P.y()) / (P.z() * P.z()));
    const double JJ = J.squaredNorm();
    if (!(JJ > 0.0)) return out;
    const double step = -J.dot(r) / JJ;
    rho += step;
    if (std::abs(step) <= 1e-12 * (1.0 + std::abs(rho))) break;
  }
  const double JJ = J.squaredNorm();
  if (!(rho > 0.0) || !(JJ > 0.0) || !std::isfinite(rho)) return out;
  out.ok = true;
  out.rho = rho;
  out.sigma = std::sqrt(2.0) * sigma_n / std::sqrt(JJ);
  return out;
}

InverseDepth transfer_inverse_depth(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                    const Eigen::Vector2d& x1, const InverseDepth& depth1) {
  InverseDepth out;
  if (!depth1.ok || !all_finite(R) || !all_finite(t) || !all_finite(x1)) return out;
  // rho2 = 1 / z2 with z2 = (R [x1; 1] / rho1 + t)_z = (Rx_z + rho1 t_z) / rho1.
  const double Rz = (R * homogeneous(x1)).z();
  const double z_times_rho1 = Rz + depth1.rho * t.z();
  if (!(z_times_rho1 > 0.0)) return out;
  out.ok = true;
  out.rho = depth1.rho / z_times_rho1;
  // d rho2 / d rho1 = Rz / (Rz + rho1 t_z)^2.
  out.sigma = std::abs(Rz) / (z_times_rho1 * z_times_rho1) * depth1.sigma;
  return out;
}

InverseDepth fuse_inverse_depths(const InverseDepth& a, const InverseDepth& b) {
  if (!a.ok) return b;
  if (!b.ok) return a;
  const double wa = 1.0 / (a.sigma * a.sigma), wb = 1.0 / (b.sigma * b.sigma);
  if (!std::isfinite(wa)) return a;
  if (!std::isfinite(wb)) return b;
  InverseDepth out;
  out.ok = true;
  out.rho = (wa * a.rho + wb * b.rho) / (wa + wb);
  out.sigma = 1.0 / std::sqrt(wa + wb);
  return out;
}

}  // namespace hybrid_vo
