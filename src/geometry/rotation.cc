#include "hybrid_vo/geometry/rotation.h"

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

Eigen::Matrix3d rotation_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = a.dot(b);
  if (c < -0.5) {
    // Flip a by a half turn about an axis orthogonal to it, then take the short arc.
    Eigen::Vector3d axis = a.cross(std::abs(a.x()) < 0.6 ? Eigen::Vector3d::UnitX()
                                                         : Eigen::Vector3d::UnitY());
    axis.normalize();
    const Eigen::Matrix3d half_turn = 2.0 * axis * axis.transpose() - Eigen::Matrix3d::Identity();
    return rotation_between(-a, b) * half_turn;
  }
  const Eigen::Matrix3d V = skew(a.cross(b));
  return Eigen::Matrix3d::Identity() + V + V * V / (1.0 + c);
}

bool rotation_from_two_directions(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
                                  const Eigen::Vector3d& b1, const Eigen::Vector3d& b2,
                                  Eigen::Matrix3d* R) {
  const Eigen::Vector3d sa = a1 + a2, da = a1 - a2, sb = b1 + b2, db = b1 - b2;
  const double ns_a = sa.norm(), nd_a = da.norm(), ns_b = sb.norm(), nd_b = db.norm();
  constexpr double kMin = 1e-9;
  if (!(ns_a > kMin && nd_a > kMin && ns_b > kMin && nd_b > kMin)) return false;
  Eigen::Matrix3d Fa, Fb;
  Fa.col(0) = sa / ns_a;
  Fa.col(1) = da / nd_a;
  Fa.col(2) = Fa.col(0).cross(Fa.col(1));
  Fb.col(0) = sb / ns_b;
  Fb.col(1) = db / nd_b;
  Fb.col(2) = Fb.col(0).cross(Fb.col(1));
  *R = Fb * Fa.transpose();
  return true;
}

Eigen::Matrix3d rotation_about(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& M) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) D(2, 2) = -1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

}  // namespace hybrid_vo
