#include "hybrid_vo/frontend/camera_model.h"

#include <cmath>

#include <Eigen/LU>

namespace hybrid_vo {
namespace {

// OpenCV's plumb-bob model on normalised coordinates (cv::projectPoints, "Camera Calibration and
// 3D Reconstruction" in the OpenCV docs), with its Jacobian when asked.
Eigen::Vector2d distort_normalized(const std::array<double, 5>& d, const Eigen::Vector2d& n,
                                   Eigen::Matrix2d* jacobian = nullptr) {
  const double k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3], k3 = d[4];
  const double x = n.x(), y = n.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const Eigen::Vector2d out(x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y);
  if (jacobian) {
    const double dradial_dr2 = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);
    const double drx = dradial_dr2 * 2.0 * x, dry = dradial_dr2 * 2.0 * y;
    (*jacobian)(0, 0) = radial + x * drx + 2.0 * p1 * y + 6.0 * p2 * x;
    (*jacobian)(0, 1) = x * dry + 2.0 * p1 * x + 2.0 * p2 * y;
    (*jacobian)(1, 0) = y * drx + 2.0 * p1 * x + 2.0 * p2 * y;
    (*jacobian)(1, 1) = radial + y * dry + 6.0 * p1 * y + 2.0 * p2 * x;
  }
  return out;
}

}  // namespace

bool CameraModel::has_distortion() const {
  for (double c : distortion)
    if (c != 0.0) return true;
  return false;
}

bool CameraModel::valid() const {
  if (!pinhole.valid()) return false;
  for (double c : distortion)
    if (!std::isfinite(c)) return false;
  return true;
}

Eigen::Vector2d CameraModel::distort(const Eigen::Vector2d& pixel) const {
  if (!has_distortion()) return pixel;
  return pinhole.denormalize(distort_normalized(distortion, pinhole.normalize(pixel)));
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& pixel) const {
  if (!has_distortion()) return pixel;
  const Eigen::Vector2d target = pinhole.normalize(pixel);
  // Newton's method on distort(n) = target from n = target, with step halving so that the
  // residual never grows (the model folds over far outside the calibrated field of view).
  // cv::undistortPoints runs the fixed-point iteration n <- (target - tangential) / radial,
  // which converges linearly; Newton reaches 1e-15 in a handful of steps.
  Eigen::Vector2d n = target;
  Eigen::Matrix2d J;
  Eigen::Vector2d residual = distort_normalized(distortion, n, &J) - target;
  for (int iteration = 0; iteration < 30 && residual.norm() > 1e-15; ++iteration) {
    const double det = J.determinant();
    if (!std::isfinite(det) || std::abs(det) < 1e-12) break;
    const Eigen::Vector2d step = J.inverse() * residual;
    double scale = 1.0;
    bool improved = false;
    for (int halving = 0; halving < 20; ++halving, scale *= 0.5) {
      const Eigen::Vector2d candidate = n - scale * step;
      Eigen::Matrix2d J_candidate;
      const Eigen::Vector2d r = distort_normalized(distortion, candidate, &J_candidate) - target;
      if (r.norm() < residual.norm()) {
        n = candidate;
        residual = r;
        J = J_candidate;
        improved = true;
        break;
      }
    }
    if (!improved) break;
  }
  return pinhole.denormalize(n);
}

void undistort_matches(const CameraModel& camera1, const CameraModel& camera2,
                       TwoViewMatches* matches) {
  if (!matches) return;
  // VP matches are directions computed from (already undistorted) segments: left as they are.
  if (camera1.has_distortion()) {
    for (PointMatch& m : matches->points) m.x1 = camera1.undistort(m.x1);
    for (LineMatch& m : matches->lines) {
      m.s1.p1 = camera1.undistort(m.s1.p1);
      m.s1.p2 = camera1.undistort(m.s1.p2);
    }
  }
  if (camera2.has_distortion()) {
    for (PointMatch& m : matches->points) m.x2 = camera2.undistort(m.x2);
    for (LineMatch& m : matches->lines) {
      m.s2.p1 = camera2.undistort(m.s2.p1);
      m.s2.p2 = camera2.undistort(m.s2.p2);
    }
  }
}

}  // namespace hybrid_vo
