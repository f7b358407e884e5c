#pragma once

#include <Eigen/Core>

namespace hybrid_vo {

// Rotation taking unit vector a onto unit vector b along the shortest arc; stable for b = -a.
Eigen::Matrix3d rotation_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

// Least-squares rotation R with R a1 ~ b1 and R a2 ~ b2 for unit vectors (closed form: the
// bisector and difference of each pair are orthogonal, so both frames are exact). False when
// a pair is (nearly) parallel.
bool rotation_from_two_directions(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
                                  const Eigen::Vector3d& b1, const Eigen::Vector3d& b2,
                                  Eigen::Matrix3d* R);

// Rotation by `angle` radians about the unit `axis` (Rodrigues).
Eigen::Matrix3d rotation_about(const Eigen::Vector3d& axis, double angle);

// Nearest rotation in the Frobenius norm (polar decomposition).
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& M);

}  // namespace hybrid_vo
