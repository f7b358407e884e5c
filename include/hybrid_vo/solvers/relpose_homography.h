#pragma once

#include <array>

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// The projective map G with G a_i ~ b_i for four homogeneous correspondences (points, or lines),
// composed from the two maps that take the projective frame e1, e2, e3, e1 + e2 + e3 onto the a_i
// and onto the b_i: a few cross products, no elimination. Unit Frobenius norm. False when three of
// the a_i or of the b_i are (nearly) collinear, or for non-finite input.
bool homography_from_4_correspondences(const Eigen::Vector3d* a, const Eigen::Vector3d* b,
                                       Eigen::Matrix3d* G);

// Same for three correspondences G a_i ~ b_i and one of the dual kind, G^T g ~ f (a line when the
// a_i are points, a point when they are lines). False when three a_i or three b_i are (nearly)
// collinear, when an a_i lies (nearly) on f or a b_i on g, or for non-finite input.
bool homography_from_3_correspondences_and_dual(const Eigen::Vector3d* a, const Eigen::Vector3d* b,
                                                const Eigen::Vector3d& f, const Eigen::Vector3d& g,
                                                Eigen::Matrix3d* G);

// Homography x2 ~ H x1 from four point matches in normalised coordinates, unit Frobenius norm:
// homography_from_4_correspondences on the centred points, written out for points (x, y, 1)
// (the 4-0-0 DLT; about a quarter of the general path's instructions). False when three points of
// either image are (nearly) collinear, or for non-finite input.
bool homography_4pt(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2, Eigen::Matrix3d* H);

// Homography from k point and 4 - k line matches of one plane (the minimal DLT, HZ2004 Sec. 4.1;
// lines map as l1 ~ H^T l2, paper eq. 2), in normalised coordinates, unit Frobenius norm. 4-0-0
// and 0-4-0 map four points or four lines, 3-1-0 and 1-3-0 three and one of the dual kind, after
// centring each image's data. False for a degenerate configuration (three collinear points, concurrent lines,
// zero-length segments, a point on one of the lines, always for 2-2-0, ...).
bool homography_from_points_and_lines(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2,
                                      int num_points, const LineSegment* s1, const LineSegment* s2,
                                      int num_lines, Eigen::Matrix3d* H);

// The homography family 4-0-0, 3-1-0, 2-2-0, 1-3-0, 0-4-0 (paper Fig. 2): DLT, then the
// decompositions (R, t) that put every point and segment in front of both cameras (usually two).
// A pure rotation gives one pose with t = 0. Requires num_points + num_lines == 4.
int relpose_homography(const Eigen::Vector2d* x1, const Eigen::Vector2d* x2, int num_points,
                       const LineSegment* s1, const LineSegment* s2, int num_lines,
                       RelativePoses* poses);

// 4-0-0: four coplanar points.
int relpose_homography_4pt(const std::array<Eigen::Vector2d, 4>& x1,
                           const std::array<Eigen::Vector2d, 4>& x2, RelativePoses* poses);
// 3-1-0: three points and one line, coplanar.
int relpose_homography_3pt_1line(const std::array<Eigen::Vector2d, 3>& x1,
                                 const std::array<Eigen::Vector2d, 3>& x2, const LineSegment& s1,
                                 const LineSegment& s2, RelativePoses* poses);
// 2-2-0: two points and two lines, coplanar. Listed by the paper, but degenerate for every input:
// the homologies with centre at the lines' junction and axis through the two points fix all four
// features, so H is only known up to a one-parameter family (HZ2004 Sec. 4.1.4): the function
// returns 0.
int relpose_homography_2pt_2line(const std::array<Eigen::Vector2d, 2>& x1,
                                 const std::array<Eigen::Vector2d, 2>& x2,
                                 const std::array<LineSegment, 2>& s1,
                                 const std::array<LineSegment, 2>& s2, RelativePoses* poses);
// 1-3-0: one point and three lines, coplanar.
int relpose_homography_1pt_3line(const Eigen::Vector2d& x1, const Eigen::Vector2d& x2,
                                 const std::array<LineSegment, 3>& s1,
                                 const std::array<LineSegment, 3>& s2, RelativePoses* poses);
// 0-4-0: four coplanar lines.
int relpose_homography_4line(const std::array<LineSegment, 4>& s1,
                             const std::array<LineSegment, 4>& s2, RelativePoses* poses);

}  // namespace hybrid_vo
