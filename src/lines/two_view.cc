#include "hybrid_vo/lines/two_view.h"

#include <chrono>

namespace hybrid_vo {

TwoViewEstimate estimate_two_view(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                  const TwoViewMatches& matches, const TwoViewOptions& options) {
  TwoViewEstimate out;
  bool uses_vps = false;
  for (const SolverInfo& info : solver_table())
    uses_vps = uses_vps || (options.ransac.enabled[static_cast<int>(info.id)] &&
                            info.num_vps > 0);
  if (!options.detect_vps || !uses_vps || !matches.vps.empty() || matches.lines.empty() ||
      !camera1.valid() || !camera2.valid()) {
    out.estimate = estimate_relative_pose(camera1, camera2, matches, options);
    return out;
  }
  const auto start = std::chrono::steady_clock::now();
  VpDetectionOptions vp_options = options.vp_detection;
  vp_options.seed = options.ransac.seed;
  out.vps = options.joint_vp_detection
                ? detect_vanishing_points_joint(camera1, camera2, matches.lines, vp_options)
                : detect_vanishing_points_standard(camera1, camera2, matches.lines, vp_options);
  out.vp_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  out.vps_detected = true;
  TwoViewMatches with_vps = matches;
  with_vps.vps = out.vps.matches;
  with_vps.line_vp = out.vps.labels;
  out.estimate = estimate_relative_pose(camera1, camera2, with_vps, options);
  return out;
}

}  // namespace hybrid_vo
