#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// Translation from two point matches when the rotation is known, e.g. held by the map of world
// directions (not one of the paper's configurations; its 2-0-2 solves t the same way once its
// VPs fix R). Each match puts t in the plane orthogonal to n = R x1 x x2, so t ~ n1 x n2, its
// sign from cheirality. Normalised coordinates. Returns 1, or 0 when the two epipolar planes
// coincide, a point is not finite, or no sign puts both points in front of both cameras.
int relpose_known_rotation_2pt(const Eigen::Matrix3d& R, const std::array<Eigen::Vector2d, 2>& x1,
                               const std::array<Eigen::Vector2d, 2>& x2, RelativePoses* poses);

}  // namespace hybrid_vo
