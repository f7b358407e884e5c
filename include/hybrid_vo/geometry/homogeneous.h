#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace hybrid_vo {

// A line segment given by its two endpoints, in pixels or in normalised image coordinates.
struct LineSegment {
  Eigen::Vector2d p1 = Eigen::Vector2d::Zero();
  Eigen::Vector2d p2 = Eigen::Vector2d::Zero();

  LineSegment() = default;
  LineSegment(const Eigen::Vector2d& a, const Eigen::Vector2d& b) : p1(a), p2(b) {}

  // Infinite line l = p1 x p2 (homogeneous, not normalised).
  Eigen::Vector3d line() const;
  double length() const { return (p2 - p1).norm(); }
  Eigen::Vector2d midpoint() const { return 0.5 * (p1 + p2); }
};

inline Eigen::Vector3d homogeneous(const Eigen::Vector2d& x) { return {x.x(), x.y(), 1.0}; }

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

// The line through two image points, scaled to unit norm of its normal (a, b) so that
// l^T x is the signed distance of x to the line. Zero vector when the points coincide.
Eigen::Vector3d line_through(const Eigen::Vector2d& a, const Eigen::Vector2d& b);

// Intersection of two homogeneous lines as an affine point. False when the lines are
// (nearly) parallel, i.e. the intersection is at or beyond `max_norm` from the origin.
bool intersect_lines(const Eigen::Vector3d& l1, const Eigen::Vector3d& l2, Eigen::Vector2d* x,
                     double max_norm = 1e8);

// True when every coefficient is finite.
template <typename Derived>
bool all_finite(const Eigen::MatrixBase<Derived>& m) {
  return ((m - m).array() == (m - m).array()).all();
}

}  // namespace hybrid_vo
