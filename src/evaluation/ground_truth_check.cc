#include "hybrid_vo/evaluation/ground_truth_check.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "hybrid_vo/evaluation/statistics.h"

namespace hybrid_vo {
namespace evaluation {

double sampson_error_px(const PinholeCamera& camera1, const PinholeCamera& camera2,
                        const RelativePose& pose, const PointMatch& match) {
  if (!(pose.t.norm() > 0.0) || !match.x1.allFinite() || !match.x2.allFinite()) return NAN;
  const Eigen::Matrix3d F =
      camera2.K().inverse().transpose() * pose.essential() * camera1.K().inverse();
  const Eigen::Vector3d a = match.x1.homogeneous(), b = match.x2.homogeneous();
  const Eigen::Vector3d Fa = F * a, Fb = F.transpose() * b;
  const double gradient = Fa.head<2>().squaredNorm() + Fb.head<2>().squaredNorm();
  if (!(gradient > 0.0)) return NAN;
  return std::abs(b.dot(Fa)) / std::sqrt(gradient);
}

double median_sampson_px(const PinholeCamera& camera1, const PinholeCamera& camera2,
                         const RelativePose& pose, const std::vector<PointMatch>& matches,
                         const std::vector<char>& mask) {
  if (!mask.empty() && mask.size() != matches.size()) return NAN;
  std::vector<double> errors;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!mask.empty() && !mask[i]) continue;
    const double e = sampson_error_px(camera1, camera2, pose, matches[i]);
    if (std::isfinite(e)) errors.push_back(e);
  }
  return median(errors);
}

double truncated_sampson_cost(const PinholeCamera& camera1, const PinholeCamera& camera2,
                              const RelativePose& pose, const std::vector<PointMatch>& matches,
                              double threshold_px) {
  if (matches.empty() || !(threshold_px > 0.0) || !std::isfinite(threshold_px)) return NAN;
  double sum = 0.0;
  for (const PointMatch& m : matches) {
    const double e = sampson_error_px(camera1, camera2, pose, m) / threshold_px;
    sum += std::isfinite(e) ? std::min(e * e, 1.0) : 1.0;
  }
  return sum / matches.size();
}

}  // namespace evaluation
}  // namespace hybrid_vo
