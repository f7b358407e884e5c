#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// A point match in pixels.
struct PointMatch {
  Eigen::Vector2d x1 = Eigen::Vector2d::Zero();
  Eigen::Vector2d x2 = Eigen::Vector2d::Zero();
};

// A line-segment match in pixels. The endpoints need not correspond.
struct LineMatch {
  LineSegment s1, s2;
};

// A vanishing-point match as directions in each camera frame (K^-1 v, any scale).
// d2 = +R d1 when sign_known, else d2 = +-R d1 (paper eq. 4).
struct VpMatch {
  Eigen::Vector3d d1 = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d d2 = Eigen::Vector3d::UnitZ();
  bool sign_known = false;
};

// What is known about a VP match's direction in camera 1 before this pair, e.g. from a VP tracked
// over earlier frames (DirectionMap::priors): a prior, not a constraint. The estimator tests it
// against the pair's point-supported rotation and, when it passes, the final refinement pulls the
// VP's direction towards it with its covariance.
struct VpPrior {
  bool valid = false;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // camera 1, unit, with d1's sign
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // rad^2, in the tangent plane
  // The prior already holds camera 1's own segments of this VP (the tracker fused them when this
  // frame was the current one): the refinement then leaves them out instead of counting twice.
  bool includes_view1 = false;
  int track_id = -1;
};

// Everything the two-view estimator consumes besides the cameras and options.
struct TwoViewMatches {
  std::vector<PointMatch> points;
  std::vector<LineMatch> lines;
  std::vector<VpMatch> vps;
  // Per line, the index of its VP in `vps`, or -1. Empty when there are no labels.
  std::vector<int> line_vp;
  // Per VP match, an optional prior on its direction. Empty when there are none.
  std::vector<VpPrior> vp_priors;
};

}  // namespace hybrid_vo
