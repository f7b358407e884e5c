#include "hybrid_vo/frontend/stereo.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace hybrid_vo {

std::vector<Eigen::Vector3d> stereo_points(const cv::Mat& left, const cv::Mat& right,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid, const StereoOptions& options) {
  std::vector<Eigen::Vector3d> X(pixels.size(), Eigen::Vector3d::Zero());
  valid->assign(pixels.size(), 0);
  if (pixels.empty() || left.empty() || right.empty() || left.size() != right.size() ||
      !camera.valid() || !(baseline_m > 0.0))
    return X;
  std::vector<cv::Point2f> from, to;
  for (const Eigen::Vector2d& p : pixels) from.emplace_back(p.x(), p.y());
  // Start the search a little to the left: right-image matches sit at smaller x.
  std::vector<uchar> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(left, right, from, to, status, error,
                           cv::Size(options.window_px, options.window_px), 3);
  for (size_t i = 0; i < pixels.size(); ++i) {
    if (!status[i]) continue;
    const double disparity = from[i].x - to[i].x;
    if (std::abs(from[i].y - to[i].y) > options.max_row_difference_px ||
        disparity < options.min_disparity_px)
      continue;
    const double Z = camera.fx * baseline_m / disparity;
    const Eigen::Vector2d n = camera.normalize(pixels[i]);
    X[i] = Z * Eigen::Vector3d(n.x(), n.y(), 1.0);
    (*valid)[i] = all_finite(X[i]);
  }
  return X;
}

bool scale_from_points(const RelativePose& unit_motion, const std::vector<Eigen::Vector3d>& X_ref,
                       const std::vector<Eigen::Vector2d>& x_cur, double* scale, int min_points) {
  std::vector<double> scales;
  const double t_norm = unit_motion.t.norm();
  if (!(t_norm > 0.0)) return false;
  for (size_t i = 0; i < X_ref.size() && i < x_cur.size(); ++i) {
    const Eigen::Vector3d x = homogeneous(x_cur[i]);
    const Eigen::Vector3d a = x.cross(unit_motion.R * X_ref[i]), b = x.cross(unit_motion.t);
    const double bb = b.squaredNorm();
    // Points seen along the direction of travel carry no scale (b ~ 0).
    if (!(bb > 1e-6 * t_norm * t_norm * x.squaredNorm())) continue;
    const double s = -a.dot(b) / bb;
    if (std::isfinite(s) && s > 0.0) scales.push_back(s);
  }
  if (static_cast<int>(scales.size()) < min_points) return false;
  std::nth_element(scales.begin(), scales.begin() + scales.size() / 2, scales.end());
  *scale = scales[scales.size() / 2];
  return true;
}

}  // namespace hybrid_vo
