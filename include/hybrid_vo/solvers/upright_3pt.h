#pragma once

#include <Eigen/Core>

namespace hybrid_vo {

// Relative pose whose rotation is about the y-axis only, q2 ~ R_y(phi) q1 + t, from three matches
// of bearing vectors (Sweeney, Flynn and Turk 2014). With y = tan(phi / 2) the three epipolar
// constraints are t . a_i(y) = 0, a_i quadratic in y; det[a_1 a_2 a_3] is a sextic with the
// factor (1 + y^2), leaving a quartic (paper Sec. 2.2.2). Writes up to 4 candidates with unit t
// (sign not fixed) and returns how many.
int upright_relpose_3pt(const Eigen::Vector3d* q1, const Eigen::Vector3d* q2, Eigen::Matrix3d* R,
                        Eigen::Vector3d* t);

// R_y(phi) in the paper's convention: [c 0 -s; 0 1 0; s 0 c].
Eigen::Matrix3d rotation_about_y(double cos_phi, double sin_phi);

}  // namespace hybrid_vo
