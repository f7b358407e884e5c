#pragma once

#include <Eigen/Core>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// The two rotations of the twisted pair and the unit translation direction (up to sign) of an
// essential matrix, without an SVD: t spans the left null space, R = cof(E) -/+ [t]x E for E
// scaled to singular values (1, 1, 0). False for a rank < 2 matrix.
bool rotations_from_essential(const Eigen::Matrix3d& E, Eigen::Matrix3d* R_a, Eigen::Matrix3d* R_b,
                              Eigen::Vector3d* t);

// Appends to `poses` the decompositions of E that put all `matches` in front of both cameras
// (usually one). Returns how many were appended.
int poses_from_essential(const Eigen::Matrix3d& E, const MatchView& matches, RelativePoses* poses);

}  // namespace hybrid_vo
