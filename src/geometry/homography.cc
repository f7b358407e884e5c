#include "hybrid_vo/geometry/homography.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {

int decompose_homography(const Eigen::Matrix3d& H_in, PlanarMotion motions[4],
                         double rotation_tolerance) {
  if (!all_finite(H_in)) return 0;
  const double det = H_in.determinant();
  if (!(std::abs(det) > 1e-14 * std::pow(H_in.norm(), 3))) return 0;
  Eigen::Matrix3d H = H_in;

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H.transpose() * H);
  if (eig.info() != Eigen::Success) return 0;
  Eigen::Vector3d lambda = eig.eigenvalues();  // ascending: sigma3^2, sigma2^2, sigma1^2
  H /= std::sqrt(lambda(1));
  lambda /= lambda(1);

  if (lambda(2) - lambda(0) < rotation_tolerance) {
    motions[0].R = nearest_rotation(H);
    motions[0].t.setZero();
    motions[0].n.setZero();
    return 1;
  }

  const Eigen::Vector3d v1 = eig.eigenvectors().col(2), v2 = eig.eigenvectors().col(1),
                        v3 = eig.eigenvectors().col(0);
  const double a = std::sqrt(std::max(0.0, 1.0 - lambda(0)));
  const double b = std::sqrt(std::max(0.0, lambda(2) - 1.0));
  const double c = std::sqrt(lambda(2) - lambda(0));
  const Eigen::Vector3d Hv2 = H * v2;
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector3d u = (a * v1 + (k == 0 ? b : -b) * v3) / c;
    const Eigen::Vector3d Hu = H * u;
    Eigen::Matrix3d U, W;
    U << v2, u, v2.cross(u);
    W << Hv2, Hu, Hv2.cross(Hu);
    PlanarMotion& m = motions[2 * k];
    m.R = W * U.transpose();
    m.n = v2.cross(u);
    m.t = (H - m.R) * m.n;
    PlanarMotion& mirrored = motions[2 * k + 1];
    mirrored.R = m.R;
    mirrored.n = -m.n;
    mirrored.t = -m.t;
  }
  return 4;
}

bool orient_homography(Eigen::Matrix3d* H, const Eigen::Vector2d* x1, const Eigen::Vector2d* x2,
                       int num_points) {
  int positive = 0, negative = 0;
  for (int i = 0; i < num_points; ++i) {
    const double s = homogeneous(x2[i]).dot(*H * homogeneous(x1[i]));
    if (s > 0.0) ++positive;
    if (s < 0.0) ++negative;
  }
  if (positive > 0 && negative > 0) return false;
  const bool flip = num_points > 0 ? negative > 0 : H->determinant() < 0.0;
  if (flip) *H = -*H;
  return true;
}

}  // namespace hybrid_vo
