#pragma once

#include <Eigen/Core>

namespace hybrid_vo {

// Pinhole intrinsics of an undistorted image (the front end undistorts points and endpoints).
struct PinholeCamera {
  double fx = 1.0, fy = 1.0, cx = 0.0, cy = 0.0;
  int width = 0, height = 0;  // 0 when unknown

  PinholeCamera() = default;
  PinholeCamera(double fx_, double fy_, double cx_, double cy_, int width_ = 0, int height_ = 0)
      : fx(fx_), fy(fy_), cx(cx_), cy(cy_), width(width_), height(height_) {}

  // Finite, with positive focal lengths: K is invertible and maps the image the right way up.
  bool valid() const;
  // Pixels to normalised coordinates (K^-1 x) and back.
  Eigen::Vector2d normalize(const Eigen::Vector2d& pixel) const {
    return {(pixel.x() - cx) / fx, (pixel.y() - cy) / fy};
  }
  Eigen::Vector2d denormalize(const Eigen::Vector2d& n) const {
    return {fx * n.x() + cx, fy * n.y() + cy};
  }
  Eigen::Matrix3d K() const;
  Eigen::Matrix3d K_inverse() const;
  double mean_focal() const { return 0.5 * (fx + fy); }
  bool in_image(const Eigen::Vector2d& pixel) const;  // true when the size is unknown
};

}  // namespace hybrid_vo
