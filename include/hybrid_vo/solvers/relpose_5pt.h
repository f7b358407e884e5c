#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// Essential matrices consistent with five point matches in normalised coordinates (Nistér 2004:
// a 10x20 elimination, a degree-10 polynomial in z, Sturm root isolation). Writes up to 10
// matrices and returns how many; 0 for degenerate (rank-deficient) or non-finite input.
int essential_5pt(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2, Eigen::Matrix3d* essentials);

// 5-0-0: relative pose from five point matches (paper Fig. 2). Every essential matrix is
// decomposed and kept when all five points are in front of both cameras. Returns the number of
// poses.
int relpose_5pt(const std::array<Eigen::Vector2d, 5>& x1, const std::array<Eigen::Vector2d, 5>& x2,
                RelativePoses* poses);

// Same, deciding cheirality on `witnesses` instead of the five points (2-3-0 passes its two points
// and three segments, since its junctions carry no depth sign).
int relpose_5pt(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2, const MatchView& witnesses,
                RelativePoses* poses);

}  // namespace hybrid_vo
