#include "hybrid_vo/estimation/motion_model_selection.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "hybrid_vo/estimation/rotation_only.h"
#include "hybrid_vo/geometry/epipolar_error.h"

namespace hybrid_vo {

MotionModelScores select_motion_model(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                      const std::vector<PointMatch>& points,
                                      const std::vector<char>& inliers, const RelativePose& full,
                                      const Eigen::Matrix3d& rotation, double sigma_px) {
  MotionModelScores s;
  if (!(sigma_px > 0.0) || !std::isfinite(sigma_px)) return s;
  // GRIC = sum min(e^2 / sigma^2, l3 (r - d)) + l1 d n + l2 k, with r = 4 (two pixels per match),
  // l1 = ln r, l2 = ln(r n), l3 = 2 (Torr's constants). The rotation's manifold distance is half
  // its transfer error squared: the nearest consistent pair moves both points by half.
  std::vector<double> sampson2, transfer2;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!inliers.empty() && (i >= inliers.size() || !inliers[i])) continue;
    const double sampson = sampson_error_px(camera1, camera2, full, points[i].x1, points[i].x2);
    const double transfer = rotation_transfer_error_px(camera1, camera2, rotation, points[i]);
    if (!std::isfinite(sampson) || !std::isfinite(transfer)) continue;
    sampson2.push_back(sampson * sampson);
    transfer2.push_back(0.5 * transfer * transfer);
  }
  s.points = static_cast<int>(sampson2.size());
  if (s.points == 0) return s;
  // The noise's mean square, not its robust sigma: tracked points are not equally precise, and
  // a sigma from the median would make every model's squares look large by the same factor,
  // which GRIC reads as structure the rotation misses. The full model's own residuals, capped
  // at its cap, give it.
  double mean_square = 0.0;
  for (const double e2 : sampson2) mean_square += std::min(e2, 2.0 * sigma_px * sigma_px);
  const double variance = std::max(sigma_px * sigma_px, mean_square / s.points);
  double full_cost = 0.0, rotation_cost = 0.0;
  for (int i = 0; i < s.points; ++i) {
    full_cost += std::min(sampson2[i] / variance, 2.0 * (4.0 - 3.0));
    rotation_cost += std::min(transfer2[i] / variance, 2.0 * (4.0 - 2.0));
  }
  const double n = s.points;
  s.gric_full = full_cost + std::log(4.0) * 3.0 * n + std::log(4.0 * n) * 5.0;
  s.gric_rotation = rotation_cost + std::log(4.0) * 2.0 * n + std::log(4.0 * n) * 3.0;
  s.rotation_only = s.gric_rotation <= s.gric_full;
  return s;
}

}  // namespace hybrid_vo
