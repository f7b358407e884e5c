#include "hybrid_vo/evaluation/ground_truth_check.h"

#include <algorithm>
#include <cmath>

#include "hybrid_vo/evaluation/statistics.h"

namespace hybrid_vo {
namespace evaluation {

double median_sampson_px(const PinholeCamera& camera1, const PinholeCamera& camera2,
                         const RelativePose& pose, const std::vector<PointMatch>& matches,
                         const std::vector<char>& mask) {
  if (!mask.empty() && mask.size() != matches.size()) return NAN;
  std::vector<double> errors;
  for (size_t i = 0; i < matches.size(); ++i) {
    if (!mask.empty() && !mask[i]) continue;
    const double e = sampson_error_px(camera1, camera2, pose, matches[i].x1, matches[i].x2);
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
    const double e = sampson_error_px(camera1, camera2, pose, m.x1, m.x2) / threshold_px;
    sum += std::isfinite(e) ? std::min(e * e, 1.0) : 1.0;
  }
  return sum / matches.size();
}

}  // namespace evaluation
}  // namespace hybrid_vo
