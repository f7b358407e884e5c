#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// Covariance (rad^2, 3x3 of rank 2, in the plane orthogonal to `direction`) of a VP direction d
// fitted to `segments` of one image with intrinsics K: the Gauss-Newton information of the
// segments' Tardif distances to v = K d (each with standard deviation sigma_px), inverted in the
// tangent plane of d. Long segments and segments far apart in direction constrain d the most.
// False (covariance untouched) when fewer than two usable segments remain, when they do not
// constrain both tangent directions, or on non-finite input.
bool vp_direction_covariance(const Eigen::Matrix3d& K, const std::vector<LineSegment>& segments,
                             const Eigen::Vector3d& direction, double sigma_px,
                             Eigen::Matrix3d* covariance);

// The covariance of a detected VP direction as a measurement: vp_direction_covariance's fit, which
// alone is optimistic (segments are not exactly straight, nor exactly parallel in the scene), plus
// vp_sigma_rad^2 per tangent axis, the VP scale measured on the pair. Returns whether the fit was
// usable; the floor is written either way.
bool vp_measurement_covariance(const Eigen::Matrix3d& K, const std::vector<LineSegment>& segments,
                               const Eigen::Vector3d& direction, double sigma_px,
                               double vp_sigma_rad, Eigen::Matrix3d* covariance);

// An orthonormal basis (3x2) of the plane orthogonal to the unit vector d.
Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& d);

// Squared Mahalanobis distance between two unit directions, sign-agnostic unless `signed_match`,
// under a covariance (3x3, rad^2) of their difference taken in the tangent plane of `a`. Returns
// infinity when the covariance is singular there or anything is not finite.
double direction_chi2(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      const Eigen::Matrix3d& covariance, bool signed_match = false);

}  // namespace hybrid_vo
