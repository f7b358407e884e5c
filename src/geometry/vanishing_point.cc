#include "hybrid_vo/geometry/vanishing_point.h"

#include <Eigen/Eigenvalues>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

Eigen::Vector3d vanishing_point_from_lines(const std::vector<Eigen::Vector3d>& lines) {
  if (lines.size() < 2) return Eigen::Vector3d::Zero();
  if (lines.size() == 2) {
    const Eigen::Vector3d v = lines[0].cross(lines[1]);
    const double n = v.norm();
    return n > 0.0 && all_finite(v) ? Eigen::Vector3d(v / n) : Eigen::Vector3d::Zero();
  }
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& l : lines) {
    const double n = l.norm();
    if (!(n > 0.0)) continue;
    M += l * l.transpose() / (n * n);
  }
  if (!all_finite(M)) return Eigen::Vector3d::Zero();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(M);
  return eig.eigenvectors().col(0);
}

}  // namespace hybrid_vo
