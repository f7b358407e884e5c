// VisualOdometry's estimation of a pair: its matches undistorted, VPs detected jointly from the
// segments and given the map's priors (VoOrientation), then the hybrid estimator.
#include <chrono>
#include <string>

#include "vo_frame.h"

namespace hybrid_vo {
namespace {

bool uses_vps(const RelativePoseEstimatorOptions& options) {
  for (const SolverInfo& info : solver_table())
    if (options.ransac.enabled[static_cast<int>(info.id)] && info.num_vps > 0) return true;
  return false;
}

}  // namespace

bool VisualOdometry::estimate(Frame& f) {
  const VisualOdometryInput& input = f.input;
  VisualOdometryResult& r = f.result;
  TwoViewMatches& m = r.matches;
  StageTimings& times = r.stages;
  const auto estimate_start = std::chrono::steady_clock::now();
  // Undistort what is still distorted (external features may come undistorted already).
  const bool points_done = input.external.has_points && input.external.points_undistorted &&
                           keyframe_.points_undistorted;
  const bool lines_done = input.external.has_lines && input.external.lines_undistorted &&
                          keyframe_.lines_undistorted;
  {
    TwoViewMatches distorted;
    if (!points_done) std::swap(distorted.points, m.points);
    if (!lines_done) std::swap(distorted.lines, m.lines);
    undistort_matches(keyframe_.camera, input.camera, &distorted);
    if (!points_done) std::swap(distorted.points, m.points);
    if (!lines_done) std::swap(distorted.lines, m.lines);
  }
  TwoViewOptions estimator = options_.estimator;
  // A share of the point budget, that share of the independent points: a pair's points are as
  // correlated as before (cpu_budget.h), and counting them as many would make its covariance
  // claim too much.
  estimator.covariance.independent_points *= point_share_;
  const auto vps_start = std::chrono::steady_clock::now();
  if (uses_vps(estimator) && !m.lines.empty()) {
    VpDetectionOptions vp_options = estimator.vp_detection;
    const MatchedVps vps = estimator.joint_vp_detection
                               ? detect_vanishing_points_joint(keyframe_.camera.pinhole,
                                                               input.camera.pinhole, m.lines,
                                                               vp_options)
                               : detect_vanishing_points_standard(keyframe_.camera.pinhole,
                                                                  input.camera.pinhole, m.lines,
                                                                  vp_options);
    m.vps = vps.matches;
    m.line_vp = vps.labels;
    r.vp_track_ids = orientation_.add_vp_priors(keyframe_.R_wc, keyframe_.R_wc_covariance,
                                                keyframe_.camera.pinhole.K(), &m);
  }
  f.vps_detected = uses_vps(estimator);
  times.vps_ms = ms_since(vps_start);
  estimator.detect_vps = false;  // detected above (or unwanted)
  const auto ransac_start = std::chrono::steady_clock::now();
  r.estimate = estimate_two_view(keyframe_.camera.pinhole, input.camera.pinhole, m, estimator);
  times.ransac_ms = ms_since(ransac_start);
  r.estimate.vps.matches = m.vps;
  r.estimate.vps.labels = m.line_vp;
  r.estimator_ms = ms_since(estimate_start);
  const EstimationStatus status = r.estimate.estimate.status;
  if (status == EstimationStatus::kOk) return true;
  r.status = VoStatus::kNoPose;
  r.message = std::string("estimator: ") + hybrid_vo::to_string(status);
  return false;
}

}  // namespace hybrid_vo
