#pragma once

#include <vector>

#include <Eigen/Core>

namespace hybrid_vo {

// Least-squares vanishing point of homogeneous lines: the unit v minimising sum (l_i^T v)^2 over
// unit-normalised l_i (for two lines, their cross product). Zero vector for fewer than two lines
// or non-finite input.
Eigen::Vector3d vanishing_point_from_lines(const std::vector<Eigen::Vector3d>& lines);

}  // namespace hybrid_vo
