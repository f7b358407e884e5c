#pragma once

#include <Eigen/Core>

namespace hybrid_vo {

// One decomposition of a calibrated homography H ~ R + t n^T: n is the unit normal of the plane
// n^T X1 = d in camera 1, and t is the translation divided by d.
struct PlanarMotion {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
};

// Decomposes H (any positive scale; the sign must satisfy lambda2 x2 = H lambda1 x1 with positive
// depths, see orient_homography) after Ma, Soatto, Kosecka and Sastry, "An Invitation to 3-D
// Vision", Sec. 5.3.3. Writes 4 motions (two pairs differing in the sign of t and n), or 1 motion
// with t = n = 0 when H is a pure rotation (relative spread of singular values below
// `rotation_tolerance`). Returns 0 for a singular or non-finite H.
int decompose_homography(const Eigen::Matrix3d& H, PlanarMotion motions[4],
                         double rotation_tolerance = 1e-10);

// Fixes the sign of a homography estimated up to scale: x2^T H x1 > 0 for point matches (both
// depths positive); without points, det(H) = d2 / d1 > 0, i.e. both cameras see the same side of
// the plane. Returns false when the points disagree among themselves.
bool orient_homography(Eigen::Matrix3d* H, const Eigen::Vector2d* x1, const Eigen::Vector2d* x2,
                       int num_points);

}  // namespace hybrid_vo
