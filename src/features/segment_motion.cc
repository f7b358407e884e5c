#include "hybrid_vo/features/segment_motion.h"

#include <cmath>

#include <Eigen/Geometry>

namespace hybrid_vo {
namespace {

double direction_angle(const LineSegment& s) {
  return std::atan2(s.p2.y() - s.p1.y(), s.p2.x() - s.p1.x());
}

double wrap_angle(double a) { return std::remainder(a, 2.0 * M_PI); }

}  // namespace

bool transfer_segment(const Eigen::Matrix3d& H, const LineSegment& s, LineSegment* out) {
  const Eigen::Vector3d a = H * homogeneous(s.p1), b = H * homogeneous(s.p2);
  if (!(std::abs(a.z()) > 1e-12) || !(std::abs(b.z()) > 1e-12)) return false;
  *out = LineSegment(a.head<2>() / a.z(), b.head<2>() / b.z());
  return all_finite(out->p1) && all_finite(out->p2);
}

SegmentMotion segment_motion_between(const LineSegment& a, const LineSegment& b, double dt) {
  // The foot of a's midpoint on b's line minus the midpoint, and the turn from a's direction to
  // b's.
  const Eigen::Vector3d l = line_through(b.p1, b.p2);
  SegmentMotion m;
  m.known = true;
  m.shift = -l.dot(homogeneous(a.midpoint())) * l.head<2>() / dt;
  m.turn = wrap_angle(direction_angle(b) - direction_angle(a)) / dt;
  return m;
}

LineSegment predict_segment(const LineSegment& s, const SegmentMotion& motion, double dt,
                            const Eigen::Matrix3d& H) {
  LineSegment carried;
  if (!transfer_segment(H, s, &carried)) carried = s;
  if (!motion.known) return carried;
  const Eigen::Vector2d mid = carried.midpoint();
  const Eigen::Vector2d moved = mid + dt * motion.shift;
  const Eigen::Rotation2Dd turn(dt * motion.turn);
  return LineSegment(moved + turn * (carried.p1 - mid), moved + turn * (carried.p2 - mid));
}

}  // namespace hybrid_vo
