#pragma once

#include <vector>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// The image motion of one frame's tracked points (KLT tracks: where each was in the last frame
// and is now), looked up near a segment: a segment moves with the surfaces around it, which the
// camera's rotation alone does not predict once it translates (at 10 Hz in a corridor, 8 px a
// frame of parallax), nor a young segment's unknown velocity.
class PointFlowField {
 public:
  // `cell_px`: the buckets' size (about the radius looked up).
  explicit PointFlowField(const std::vector<PointMatch>& motions = {}, double cell_px = 40.0);
  // Where segment `s` of the last frame moves by the points within `radius_px` of it (of its
  // line, and along it within its ends and radius_px beyond): each end by the median motion of
  // the points on its half, the motion along the segment interpolated between the halves (a
  // segment turns), or both by the median of all when a half has fewer than two. False with fewer
  // than `min_points` near it. `spread_px` receives how much their motions across the segment
  // differ (a robust sigma): an occluding edge moves with one side only.
  bool predict(const LineSegment& s, double radius_px, int min_points, LineSegment* predicted,
               double* spread_px) const;
  bool empty() const { return motions_.empty(); }

 private:
  std::vector<PointMatch> motions_;
  double cell_ = 40.0;
  int cols_ = 0, rows_ = 0;
  double x0_ = 0.0, y0_ = 0.0;
  std::vector<std::vector<int>> cells_;  // point indices per bucket, by where they were
};

}  // namespace hybrid_vo
