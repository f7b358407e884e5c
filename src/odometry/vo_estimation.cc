// VisualOdometry's estimation of a pair: its matches undistorted, VPs detected jointly from the
// segments and given the map's priors (VoOrientation), then the hybrid estimator, or, where the
// data show no translation, the rotation alone (rotation_only.h) from every modality.
#include <chrono>
#include <limits>
#include <string>

#include "hybrid_vo/estimation/motion_model_selection.h"
#include "vo_frame.h"

namespace hybrid_vo {
namespace {

bool uses_vps(const RelativePoseEstimatorOptions& options) {
  for (const SolverInfo& info : solver_table())
    if (options.ransac.enabled[static_cast<int>(info.id)] && info.num_vps > 0) return true;
  return false;
}

}  // namespace

TwoViewOptions VisualOdometry::pair_options() const {
  TwoViewOptions estimator = options_.estimator;
  // A share of the point budget, that share of the independent points: a pair's points are as
  // correlated as before (cpu_budget.h), and counting them as many would make its covariance
  // claim too much.
  estimator.covariance.independent_points *= point_share_;
  return estimator;
}

void VisualOdometry::prepare_pair(Frame& f) {
  const VisualOdometryInput& input = f.input;
  VisualOdometryResult& r = f.result;
  TwoViewMatches& m = r.matches;
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
  const TwoViewOptions estimator = pair_options();
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
  r.stages.vps_ms = ms_since(vps_start);
  r.estimator_ms = ms_since(estimate_start);
}

bool VisualOdometry::estimate(Frame& f) {
  const VisualOdometryInput& input = f.input;
  VisualOdometryResult& r = f.result;
  const auto ransac_start = std::chrono::steady_clock::now();
  TwoViewOptions estimator = pair_options();
  estimator.detect_vps = false;  // detected by prepare_pair (or unwanted)
  r.estimate = estimate_two_view(keyframe_.camera.pinhole, input.camera.pinhole, r.matches,
                                 estimator);
  r.stages.ransac_ms = ms_since(ransac_start);
  r.estimate.vps.matches = r.matches.vps;
  r.estimate.vps.labels = r.matches.line_vp;
  r.estimator_ms += r.stages.ransac_ms;
  const EstimationStatus status = r.estimate.estimate.status;
  if (status != EstimationStatus::kOk) {
    r.status = VoStatus::kNoPose;
    r.message = std::string("estimator: ") + hybrid_vo::to_string(status);
    return false;
  }
  // Does the translation hold? Where the points' noise explains what the rotation leaves of
  // their motion (GRIC), the pair is answered by its rotation alone.
  const RelativePoseEstimate& est = r.estimate.estimate;
  if (options_.rotation_only_pairs && options_.model_selection && f.rotation.ok) {
    const MotionModelScores scores = select_motion_model(
        keyframe_.camera.pinhole, input.camera.pinhole, r.matches.points, est.point_inliers,
        est.pose, f.rotation.R, est.scales.point_px);
    // A full model whose refinement found no covariance (its translation left it singular) does
    // not hold that translation either: the rotation alone can say how well it is known (a pan
    // whose tracks drifted: the map took such a pair for a blank wall and moved it by a degree).
    f.rotation_only = scores.rotation_only || !est.covariance_valid;
    r.message = std::string(f.rotation_only ? "no translation seen" : "translation seen") +
                " (GRIC per point: rotation " + std::to_string(scores.gric_rotation / scores.points) +
                ", full " + std::to_string(scores.gric_full / scores.points) + ")";
  }
  return true;
}

bool VisualOdometry::estimate_rotation(Frame& f) {
  const VisualOdometryInput& input = f.input;
  VisualOdometryResult& r = f.result;
  const auto start = std::chrono::steady_clock::now();
  const TwoViewOptions estimator = pair_options();
  const Eigen::Matrix3d initial = f.rotation.R;
  const RotationOnlyEstimate rotation =
      estimate_rotation_only(keyframe_.camera.pinhole, input.camera.pinhole, r.matches,
                             options_.rotation_only, estimator.covariance,
                             f.rotation.ok ? &initial : nullptr);
  r.stages.ransac_ms += ms_since(start);
  r.estimator_ms += ms_since(start);
  if (!rotation.ok) {
    r.status = VoStatus::kLowParallax;
    r.message += "; no rotation found";
    return false;
  }
  f.rotation = rotation;
  // In the estimate's form, for the orientation, the scale's observations and the statistics.
  RelativePoseEstimate& est = r.estimate.estimate;
  est = RelativePoseEstimate();
  est.status = EstimationStatus::kOk;
  est.pose = RelativePose(rotation.R, Eigen::Vector3d::Zero());
  est.covariance.topLeftCorner<3, 3>() = rotation.covariance;
  est.hessian_covariance = est.covariance;
  est.covariance_valid = rotation.covariance_valid;
  est.point_inliers = rotation.point_inliers;
  est.line_inliers = rotation.line_inliers;
  est.vp_inliers = rotation.vp_inliers;
  est.num_point_inliers = rotation.num_point_inliers;
  est.num_line_inliers = rotation.num_line_inliers;
  est.num_vp_inliers = rotation.num_vp_inliers;
  const ModalityScaleOptions& defaults = estimator.scales;
  est.scales.point_px = rotation.point_sigma_px;
  est.scales.line_vp_px = defaults.default_fraction * defaults.line_threshold_px;
  est.scales.vp_deg = rotation.vp_sigma_deg > 0.0
                          ? rotation.vp_sigma_deg
                          : defaults.default_fraction * estimator.ransac.vp_threshold_deg;
  est.iterations = rotation.iterations;
  est.vp_prior_chi2.assign(r.matches.vps.size(), std::numeric_limits<double>::quiet_NaN());
  est.vp_prior_used.assign(r.matches.vps.size(), 0);
  r.estimate.vps.matches = r.matches.vps;
  r.estimate.vps.labels = r.matches.line_vp;
  r.status = VoStatus::kRotationOnly;
  r.message = (r.message.empty() ? std::string("rotation only") : r.message);
  return true;
}

}  // namespace hybrid_vo
