#pragma once

#include <Eigen/Core>

namespace hybrid_vo {

// A rotation about the y-axis, R_y(phi) = [c 0 -s; 0 1 0; s 0 c], and a unit translation.
struct UprightPose {
  double cos_phi = 1.0, sin_phi = 0.0;
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};

// Relative pose whose rotation is about the y-axis only, q2 ~ R_y(phi) q1 + t, from three matches
// of bearing vectors (Sweeney, Flynn and Turk 2014). With y = tan(phi / 2) the three epipolar
// constraints are t . a_i(y) = 0, a_i quadratic in y; det[a_1 a_2 a_3] is a sextic with the
// factor (1 + y^2), leaving a quartic (paper Sec. 2.2.2). Writes up to 4 candidates and returns
// how many. With `orient`, the sign of each t puts the three points in front of both cameras
// (orient_translation_rays) and candidates for which no sign does are dropped; otherwise the
// sign of t is not fixed.
int upright_relpose_3pt(const Eigen::Vector3d* q1, const Eigen::Vector3d* q2, bool orient,
                        UprightPose* poses);

// R_y(phi) in the paper's convention: [c 0 -s; 0 1 0; s 0 c].
Eigen::Matrix3d rotation_about_y(double cos_phi, double sin_phi);

}  // namespace hybrid_vo
