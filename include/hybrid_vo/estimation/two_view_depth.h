#pragma once

// A point's inverse depth in the second camera of a pair, triangulated from its match: what a
// monocular keyframe knows of its points, so that the next pair's translation gets the length
// that agrees with them (the relative scale of monocular odometry; Scaramuzza and Fraundorfer,
// "Visual Odometry, Part I", 2011, section "2D-to-2D: motion from image feature
// correspondences"). The depth is in the units of t.

#include <Eigen/Core>

namespace hybrid_vo {

struct InverseDepth {
  bool ok = false;
  double rho = 0.0;    // 1 / depth along the second camera's z axis
  double sigma = 0.0;  // its standard deviation
};

// The match x1 (camera 1) <-> x2 (camera 2), normalised image coordinates, of a pair X2 = R X1 + t
// with a non-zero t. The point lies on x2's ray, X2 = [x2; 1] / rho, at the rho whose projection
// into camera 1 is nearest to x1 (Gauss-Newton from the linear solution). `sigma_n` is the
// noise of a normalised coordinate (pixels over the focal length), in both images: the sigma
// follows to first order. Not ok when the point is behind either camera, lies along t (no
// parallax), or an input is not finite.
InverseDepth triangulate_inverse_depth(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                       const Eigen::Vector2d& x1, const Eigen::Vector2d& x2,
                                       double sigma_n);

// A point's inverse depth in camera 1 moved into camera 2 of a pair X2 = R X1 + t (its ray x1),
// the sigma carried to first order; not ok when it falls behind camera 2.
InverseDepth transfer_inverse_depth(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                    const Eigen::Vector2d& x1, const InverseDepth& depth1);

// Two estimates of the same inverse depth combined by their variances (either may be missing).
InverseDepth fuse_inverse_depths(const InverseDepth& a, const InverseDepth& b);

}  // namespace hybrid_vo
