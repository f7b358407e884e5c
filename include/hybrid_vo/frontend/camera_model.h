#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// Pinhole intrinsics plus OpenCV's plumb-bob distortion (k1, k2, p1, p2, k3). The core works on
// undistorted pixels, so the front end undistorts points and segment endpoints with this model.
struct CameraModel {
  PinholeCamera pinhole;
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};

  bool has_distortion() const;
  bool valid() const;  // pinhole valid and coefficients finite
  // Distorted pixels to undistorted pixels of the same pinhole (iterative inversion).
  Eigen::Vector2d undistort(const Eigen::Vector2d& pixel) const;
  // Undistorted to distorted pixels (the forward model), e.g. for rendering.
  Eigen::Vector2d distort(const Eigen::Vector2d& pixel) const;
};

// Undistorts every point and segment endpoint of the matches in place (each image with its own
// model). Straight 3D lines are curved under distortion; undistorting the endpoints is exact for
// the endpoints and a good approximation of the line between them for the short segments LSD
// returns.
void undistort_matches(const CameraModel& camera1, const CameraModel& camera2,
                       TwoViewMatches* matches);

}  // namespace hybrid_vo
