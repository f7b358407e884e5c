#include "hybrid_vo/features/camera_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

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

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The equidistant model's radius theta_d(theta) (cv::fisheye's), with its derivative when asked.
double equidistant_radius(const std::array<double, 5>& k, double theta,
                          double* derivative = nullptr) {
  const double t2 = theta * theta;
  if (derivative)
    *derivative =
        1.0 + t2 * (3.0 * k[0] + t2 * (5.0 * k[1] + t2 * (7.0 * k[2] + t2 * 9.0 * k[3])));
  return theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
}

// The angle off the axis of a distorted radius: Newton's method from theta = theta_d, with step
// halving so that the residual never grows, on [0, pi] and the increasing branch; NaN when it
// does not converge there.
double equidistant_angle(const std::array<double, 5>& k, double theta_d) {
  if (!(theta_d >= 0.0) || !std::isfinite(theta_d)) return kNaN;
  if (theta_d == 0.0) return 0.0;
  double theta = std::min(theta_d, M_PI), slope = 0.0;
  double residual = equidistant_radius(k, theta, &slope) - theta_d;
  for (int iteration = 0; iteration < 50 && std::abs(residual) > 1e-14; ++iteration) {
    if (!(slope > 0.0)) return kNaN;
    const double step = residual / slope;
    bool improved = false;
    for (double scale = 1.0; scale > 1e-6; scale *= 0.5) {
      const double candidate = std::clamp(theta - scale * step, 0.0, M_PI);
      double candidate_slope = 0.0;
      const double r = equidistant_radius(k, candidate, &candidate_slope) - theta_d;
      if (std::abs(r) < std::abs(residual)) {
        theta = candidate;
        residual = r;
        slope = candidate_slope;
        improved = true;
        break;
      }
    }
    if (!improved) break;
  }
  if (!(std::abs(residual) <= 1e-10 * (1.0 + theta_d)) || !(slope > 0.0)) return kNaN;
  return theta;
}

}  // namespace

const char* to_string(LensModel model) {
  return model == LensModel::kEquidistant ? "equidistant" : "plumb_bob";
}

bool CameraModel::has_distortion() const {
  if (model == LensModel::kEquidistant) return true;
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
  const Eigen::Vector2d n = pinhole.normalize(pixel);
  if (model == LensModel::kEquidistant) {
    const double r = n.norm();
    if (r == 0.0) return pixel;
    return pinhole.denormalize(n * (equidistant_radius(distortion, std::atan(r)) / r));
  }
  return pinhole.denormalize(distort_normalized(distortion, n));
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& pixel) const {
  if (!has_distortion()) return pixel;
  const Eigen::Vector2d target = pinhole.normalize(pixel);
  if (model == LensModel::kEquidistant) {
    const double theta_d = target.norm();
    if (theta_d == 0.0) return pixel;
    const double theta = equidistant_angle(distortion, theta_d);
    // At 90 degrees and beyond there is no pinhole pixel (also NaN from a failed inversion).
    if (!(theta < 0.5 * M_PI - 1e-9)) return Eigen::Vector2d(kNaN, kNaN);
    return pinhole.denormalize(target * (std::tan(theta) / theta_d));
  }
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

Eigen::Vector3d CameraModel::ray(const Eigen::Vector2d& pixel) const {
  if (model == LensModel::kEquidistant) {
    const Eigen::Vector2d d = pinhole.normalize(pixel);
    const double theta_d = d.norm();
    if (theta_d == 0.0) return Eigen::Vector3d::UnitZ();
    const double theta = equidistant_angle(distortion, theta_d);
    if (!std::isfinite(theta)) return Eigen::Vector3d::Constant(kNaN);
    const Eigen::Vector2d side = std::sin(theta) * d / theta_d;
    return Eigen::Vector3d(side.x(), side.y(), std::cos(theta));
  }
  const Eigen::Vector2d n = pinhole.normalize(undistort(pixel));
  return Eigen::Vector3d(n.x(), n.y(), 1.0).normalized();
}

bool CameraModel::project(const Eigen::Vector3d& point, Eigen::Vector2d* pixel) const {
  if (model == LensModel::kEquidistant) {
    const double r = point.head<2>().norm();
    if (r == 0.0 && !(point.z() > 0.0)) return false;  // the backward axis, or the centre
    const double theta = std::atan2(r, point.z());
    const Eigen::Vector2d d = r == 0.0 ? Eigen::Vector2d::Zero()
                                       : Eigen::Vector2d(point.head<2>() *
                                                         (equidistant_radius(distortion, theta) / r));
    *pixel = pinhole.denormalize(d);
    return all_finite(*pixel);
  }
  if (!(point.z() > 0.0)) return false;
  *pixel = distort(pinhole.denormalize(point.head<2>() / point.z()));
  return all_finite(*pixel);
}

std::string camera_model_problem(const CameraModel& camera) {
  if (!camera.pinhole.valid()) return "invalid focal length or principal point";
  for (double c : camera.distortion)
    if (!std::isfinite(c)) return "a non-finite distortion coefficient";
  if (camera.model != LensModel::kEquidistant) return "";
  // The farthest corner's distorted radius must be reached while theta_d still grows (or not at
  // all: a circular fisheye image leaves its corners dark).
  const PinholeCamera& p = camera.pinhole;
  double corner = 0.0;
  for (double x : {-0.5, p.width - 0.5})
    for (double y : {-0.5, p.height - 0.5}) corner = std::max(corner, p.normalize({x, y}).norm());
  const int steps = 1800;  // 0.1 degree
  for (int i = 0; i <= steps; ++i) {
    const double theta = M_PI * i / steps;
    double slope = 0.0;
    const double radius = equidistant_radius(camera.distortion, theta, &slope);
    if (radius >= corner) break;
    if (!(slope > 0.0)) {
      char why[160];
      std::snprintf(why, sizeof(why),
                    "the equidistant coefficients fold back at %.1f deg off the axis, inside "
                    "the image (its corner needs theta_d = %.3f)",
                    theta * 180.0 / M_PI, corner);
      return why;
    }
  }
  return "";
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
