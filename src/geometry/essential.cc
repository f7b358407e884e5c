#include "hybrid_vo/geometry/essential.h"

#include <cmath>

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {

bool rotations_from_essential(const Eigen::Matrix3d& E, Eigen::Matrix3d* R_a, Eigen::Matrix3d* R_b,
                              Eigen::Vector3d* t) {
  const double norm = E.norm();
  if (!(norm > 0.0) || !all_finite(E)) return false;
  const Eigen::Matrix3d En = E * (std::sqrt(2.0) / norm);
  // Every column of [t]x R is orthogonal to t; take the best-conditioned pair.
  const Eigen::Vector3d c01 = En.col(0).cross(En.col(1)), c02 = En.col(0).cross(En.col(2)),
                        c12 = En.col(1).cross(En.col(2));
  const double n01 = c01.squaredNorm(), n02 = c02.squaredNorm(), n12 = c12.squaredNorm();
  Eigen::Vector3d dir = c01;
  double best = n01;
  if (n02 > best) dir = c02, best = n02;
  if (n12 > best) dir = c12, best = n12;
  if (!(best > 1e-20)) return false;
  *t = dir / std::sqrt(best);
  Eigen::Matrix3d cof;
  cof.row(0) = En.row(1).cross(En.row(2));
  cof.row(1) = En.row(2).cross(En.row(0));
  cof.row(2) = En.row(0).cross(En.row(1));
  const Eigen::Matrix3d tE = skew(*t) * En;
  *R_a = cof - tE;
  *R_b = cof + tE;
  // Exact only for an exact essential matrix; a solver's near-essential E (e.g. from a badly
  // conditioned root) is projected onto SO(3), which is rare enough to afford an SVD.
  for (Eigen::Matrix3d* R : {R_a, R_b})
    if ((R->transpose() * *R - Eigen::Matrix3d::Identity()).lpNorm<Eigen::Infinity>() > 1e-10)
      *R = nearest_rotation(*R);
  return true;
}

int poses_from_essential(const Eigen::Matrix3d& E, const MatchView& matches, RelativePoses* poses) {
  Eigen::Matrix3d R_a, R_b;
  Eigen::Vector3d t;
  if (!rotations_from_essential(E, &R_a, &R_b, &t)) return 0;
  int added = 0;
  for (const Eigen::Matrix3d* R : {&R_a, &R_b}) {
    Eigen::Vector3d t_oriented = t;
    if (!orient_translation(*R, &t_oriented, matches)) continue;
    poses->emplace_back(*R, t_oriented);
    ++added;
  }
  return added;
}

}  // namespace hybrid_vo
