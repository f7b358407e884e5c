#pragma once

// How a segment moves between frames, shared by the segment trackers (line_tracker.cc,
// line_flow_tracker.cc): carried by the camera's rotation (an image homography), and by its own
// image motion beyond that.

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// A segment's own image motion per unit of time beyond the camera's rotation: the shift of its
// line along its normal at the midpoint and the turn of its direction; unknown until seen twice.
struct SegmentMotion {
  bool known = false;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  double turn = 0.0;
};

// A segment's endpoints carried by a homography; false when one lands at infinity.
bool transfer_segment(const Eigen::Matrix3d& H, const LineSegment& s, LineSegment* out);

// The motion from `a` (carried by the rotation) to `b`, seen `dt` later (dt > 0).
SegmentMotion segment_motion_between(const LineSegment& a, const LineSegment& b, double dt);

// Where segment `s`, seen `dt` ago and moving by `motion`, lies now, first carried by `H` (left
// where it is when H sends it to infinity).
LineSegment predict_segment(const LineSegment& s, const SegmentMotion& motion, double dt,
                            const Eigen::Matrix3d& H);

}  // namespace hybrid_vo
