#include "hybrid_vo/geometry/cheirality.h"

#include <Eigen/Geometry>

namespace hybrid_vo {
namespace {

// Each witness votes +1 (t as given), -1 (t flipped), 0 (no information) or reports a conflict
// (cheirality_vote in the header); combine_cheirality_votes folds the votes.

// One point match as rays in camera 2's frame (or any rotation of it, applied to all three):
// r = R x1 and q = x2, each up to a positive scale; tt = |t|^2. Written out in scalars, since the
// minimal solvers call this several times per candidate pose.
int vote_of_rays(double rx, double ry, double rz, double qx, double qy, double qz,
                 const Eigen::Vector3d& t, double tt) {
  return cheirality_vote(rx * rx + ry * ry + rz * rz, qx * qx + qy * qy + qz * qz,
                         qx * rx + qy * ry + qz * rz, qx * t.x() + qy * t.y() + qz * t.z(),
                         rx * t.x() + ry * t.y() + rz * t.z(), tt);
}

int vote_of_point(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double tt,
                  const Eigen::Vector2d& x1, const Eigen::Vector2d& x2) {
  const double rx = R(0, 0) * x1.x() + R(0, 1) * x1.y() + R(0, 2);
  const double ry = R(1, 0) * x1.x() + R(1, 1) * x1.y() + R(1, 2);
  const double rz = R(2, 0) * x1.x() + R(2, 1) * x1.y() + R(2, 2);
  return vote_of_rays(rx, ry, rz, x2.x(), x2.y(), 1.0, t, tt);
}

// Depth of image point a (camera `from`) on the plane back-projected from line l of the other
// camera, as sign(numerator * denominator); the plane contains the baseline when num ~ 0. The
// scales are squared.
int vote_of_endpoint(double num, double num_scale2, double den, double den_scale2) {
  if (!(num * num > kCheiralityNoParallax2 * num_scale2) ||
      !(den * den > kCheiralityNoParallax2 * den_scale2))
    return 0;
  return (num > 0.0) == (den > 0.0) ? 1 : -1;
}

int vote_of_segment(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double tt,
                    const LineSegment& s1, const LineSegment& s2) {
  const Eigen::Vector3d l1 = s1.line(), l2 = s2.line();
  const double n1 = l1.squaredNorm(), n2 = l2.squaredNorm();
  if (!(n1 > 0.0 && n2 > 0.0 && tt > 0.0)) return 0;
  int sign = 0;
  // Camera 1 endpoint a: depth = -(l2.t) / (l2.R a).
  const double l2t = l2.dot(t);
  for (const Eigen::Vector2d* a : {&s1.p1, &s1.p2}) {
    const Eigen::Vector3d ra = R * homogeneous(*a);
    sign = combine_cheirality_votes(
        sign, vote_of_endpoint(-l2t, n2 * tt, l2.dot(ra), n2 * ra.squaredNorm()));
  }
  // Camera 2 endpoint b: depth = (l1.R^T t) / (l1.R^T b).
  const Eigen::Vector3d Rl1 = R * l1;
  const double l1t = Rl1.dot(t);
  for (const Eigen::Vector2d* b : {&s2.p1, &s2.p2}) {
    const Eigen::Vector3d hb = homogeneous(*b);
    sign = combine_cheirality_votes(
        sign, vote_of_endpoint(l1t, n1 * tt, Rl1.dot(hb), n1 * hb.squaredNorm()));
  }
  return sign;
}

}  // namespace

int orient_translation_by_majority(const Eigen::Matrix3d& R, Eigen::Vector3d* t,
                                   const MatchView& matches) {
  int positive = 0, negative = 0;
  const double tt = t->squaredNorm();
  for (int i = 0; i < matches.num_points; ++i) {
    const int vote = vote_of_point(R, *t, tt, matches.x1[i], matches.x2[i]);
    positive += vote == 1;
    negative += vote == -1;
  }
  for (int i = 0; i < matches.num_segments; ++i) {
    const int vote = vote_of_segment(R, *t, tt, matches.s1[i], matches.s2[i]);
    positive += vote == 1;
    negative += vote == -1;
  }
  if (negative > positive) *t = -*t;
  return std::abs(positive - negative);
}

bool orient_translation_rays(const Eigen::Vector3d* r, const Eigen::Vector3d* q, int n,
                             Eigen::Vector3d* t) {
  int sign = 0;
  const double tt = t->squaredNorm();
  for (int i = 0; i < n && sign != kCheiralityConflict; ++i)
    sign = combine_cheirality_votes(
        sign, vote_of_rays(r[i].x(), r[i].y(), r[i].z(), q[i].x(), q[i].y(), q[i].z(), *t, tt));
  if (sign == kCheiralityConflict) return false;
  if (sign < 0) *t = -*t;
  return true;
}

bool orient_translation(const Eigen::Matrix3d& R, Eigen::Vector3d* t, const MatchView& matches) {
  int sign = 0;
  const double tt = t->squaredNorm();
  for (int i = 0; i < matches.num_points && sign != kCheiralityConflict; ++i)
    sign = combine_cheirality_votes(sign, vote_of_point(R, *t, tt, matches.x1[i], matches.x2[i]));
  for (int i = 0; i < matches.num_segments && sign != kCheiralityConflict; ++i)
    sign = combine_cheirality_votes(sign, vote_of_segment(R, *t, tt, matches.s1[i], matches.s2[i]));
  if (sign == kCheiralityConflict) return false;
  if (sign < 0) *t = -*t;
  return true;
}

}  // namespace hybrid_vo
