#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// The lens models of camera_info's distortion_model that the front end takes.
enum class LensModel {
  // plumb_bob (and rational_polynomial without its k4..k6): OpenCV's k1, k2, p1, p2, k3.
  kRadialTangential,
  // equidistant (OpenCV's cv::fisheye, Kalibr's pinhole-equi): a ray at angle theta to the
  // optical axis lands at radius theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 +
  // k4 theta^8) in normalised coordinates; coefficients k1..k4 in distortion[0..3].
  kEquidistant,
};
const char* to_string(LensModel model);  // "plumb_bob", "equidistant"

// Pinhole intrinsics plus a lens model. The core works on undistorted pixels (the pinhole's), so
// the front end undistorts points and segment endpoints with this model; a strong fisheye is
// rectified into a pinhole view instead (fisheye_rectifier.h).
struct CameraModel {
  PinholeCamera pinhole;
  LensModel model = LensModel::kRadialTangential;
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};

  // False only for the radial-tangential model with all coefficients zero (an equidistant lens
  // is never a pinhole).
  bool has_distortion() const;
  bool valid() const;  // pinhole valid and coefficients finite
  // Distorted pixels to undistorted pixels of the same pinhole (iterative inversion). An
  // equidistant pixel whose ray is 90 degrees or more off the axis has no pinhole pixel: NaN.
  Eigen::Vector2d undistort(const Eigen::Vector2d& pixel) const;
  // Undistorted to distorted pixels (the forward model), e.g. for rendering.
  Eigen::Vector2d distort(const Eigen::Vector2d& pixel) const;
  // The unit ray (camera frame, z forward) a pixel sees, also beyond 90 degrees for the
  // equidistant model; NaN where the model cannot be inverted.
  Eigen::Vector3d ray(const Eigen::Vector2d& pixel) const;
  // The pixel of a camera-frame point: in front of the camera for the pinhole, anywhere but on
  // the backward axis for the equidistant model. False where there is none.
  bool project(const Eigen::Vector3d& point, Eigen::Vector2d* pixel) const;
};

// Why a camera cannot be used, or empty: an invalid pinhole, non-finite coefficients, or an
// equidistant polynomial that folds back (theta_d stops growing) before the image's farthest
// corner, where undistortion would be ambiguous.
std::string camera_model_problem(const CameraModel& camera);

// Undistorts every point and segment endpoint of the matches in place (each image with its own
// model). Straight 3D lines are curved under distortion; undistorting the endpoints is exact for
// the endpoints and a good approximation of the line between them for the short segments LSD
// returns. A point without a pinhole pixel (an equidistant ray 90 degrees or more off the axis)
// becomes NaN, which the estimator leaves out.
void undistort_matches(const CameraModel& camera1, const CameraModel& camera2,
                       TwoViewMatches* matches);

}  // namespace hybrid_vo
