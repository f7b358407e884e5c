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

// Everything the two-view estimator consumes besides the cameras and options.
struct TwoViewMatches {
  std::vector<PointMatch> points;
  std::vector<LineMatch> lines;
  std::vector<VpMatch> vps;
  // Per line, the index of its VP in `vps`, or -1. Empty when there are no labels.
  std::vector<int> line_vp;
};

}  // namespace hybrid_vo
