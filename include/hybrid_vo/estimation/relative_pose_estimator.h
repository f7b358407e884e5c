#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/derived_matches.h"
#include "hybrid_vo/estimation/final_refinement.h"
#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/estimation/modality_scales.h"
#include "hybrid_vo/estimation/pair_covariance.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/geometry/pose.h"
#include "hybrid_vo/solvers/minimal_solver.h"

namespace hybrid_vo {

// Hybrid RANSAC over the minimal solvers (paper Sec. 4, after Camposeco et al. 2018).
struct HybridRansacOptions {
  // Which solvers may be drawn, and their prior weights. 2-2-0 is degenerate and stays off.
  std::array<bool, kNumSolvers> enabled;
  std::array<double, kNumSolvers> prior;
  // Inlier thresholds: Sampson error of point-like matches in pixels, angle of VP matches.
  double point_threshold_px = 1.0;
  double vp_threshold_deg = 2.0;
  // A line match alone cannot be verified by a relative pose, so solver selection uses a preset
  // line inlier ratio (paper Sec. 4). Termination uses the measured support instead (lines with
  // an inlier junction or agreeing with an inlier VP), a lower bound. Points and VPs start from
  // the initial ratios until a model measures them.
  double line_inlier_ratio = 0.6;
  double initial_point_inlier_ratio = 0.5;
  double initial_vp_inlier_ratio = 0.8;
  // Share of draws spread uniformly over the available solvers, the rest following the adaptive
  // probabilities: keeps every solver in play when the current best model is wrong.
  double exploration = 0.2;
  // Share of the draws reserved for the 5-point solver when other solvers are active too, so that
  // the hybrid searches the point-only solution at least half as well as 5pc and the line and VP
  // solvers add models rather than replace them. The adaptive selection favours VP solvers (their
  // samples are small), and with a few dozen 5-point draws the hybrid lost 10 AUC@10 points to
  // 5pc on TUM at gap 2 where few point inliers remain.
  double five_point_share = 0.5;
  // Stop once the draws of every solver (homography solvers only when nothing else is enabled)
  // together have missed an all-inlier sample with probability below 1 - confidence, but not
  // before min_iterations. VP solvers reach that bound within a few draws, yet an all-inlier
  // sample of noisy VPs can still give a wrong translation in forward motion (KITTI): 150 draws
  // fixed every such pair on KITTI at ~1 ms (doc/pairs.md).
  double confidence = 0.999;
  int min_iterations = 150;
  int max_iterations = 5000;
  // Local optimisation (Levenberg-Marquardt on a subset of the inliers) of every new best model.
  bool local_optimization = true;
  int lo_max_points = 256;
  int lo_rounds = 4;  // refine, re-select inliers, refine again while the cost drops
  // VPs whose directions are within this angle of orthogonal count as orthogonal (Manhattan),
  // so that lines of one serve as the orthogonal line of the other (2-1-1, 1-2-1, 2-0-1).
  double orthogonal_tolerance_deg = 10.0;
  uint64_t seed = 0;

  HybridRansacOptions();
};

template <typename Visit>
void visit_fields(HybridRansacOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(any_value(), o.enabled, o.local_optimization, o.seed);
  HYBRID_VO_FIELDS(non_negative(), o.prior, o.min_iterations, o.lo_rounds,
                  o.orthogonal_tolerance_deg);
  HYBRID_VO_FIELDS(positive(), o.point_threshold_px, o.vp_threshold_deg, o.max_iterations,
                  o.lo_max_points);
  HYBRID_VO_FIELDS(fraction(), o.line_inlier_ratio, o.initial_point_inlier_ratio,
                  o.initial_vp_inlier_ratio, o.exploration, o.five_point_share);
  HYBRID_VO_FIELDS(open_fraction(), o.confidence);
}

struct RelativePoseEstimatorOptions {
  HybridRansacOptions ransac;
  // Point-like data besides the point matches; line solvers use junctions either way.
  bool use_junction_points = false;
  bool use_endpoint_points = false;
  JunctionOptions junctions;
  // The refinement's sigmas come from the pair's own inliers (ModalityScales) unless disabled,
  // its Cauchy scales from the inlier thresholds; its other settings (and whether it runs at
  // all) from `refinement`.
  ModalityScaleOptions scales;
  FinalRefinementOptions refinement;
  // The covariance reported (RelativePoseEstimate::covariance): the refinement's, weighed by
  // what the pair's residuals cannot show (pair_covariance.h).
  PairCovarianceOptions covariance;
  // A VP prior (TwoViewMatches::vp_priors) is used only when its direction, carried by the best
  // RANSAC model's rotation, agrees with the VP seen in image 2: the squared Mahalanobis distance
  // under both covariances must not exceed this (chi-square, 2 dof: 9.21 at 99 %).
  double vp_prior_gate_chi2 = 9.21;
  // Below this many point-like inliers (and no inlier VP pair to fix the rotation), the best model
  // is not trusted and the status is kNoModel.
  int min_point_inliers = 5;
};

// The ransac fields without a prefix (the estimator's main knobs), each other component under its
// member's name.
template <typename Visit>
void visit_fields(RelativePoseEstimatorOptions& o, Visit&& visit) {
  visit_fields(o.ransac, visit);
  HYBRID_VO_FIELDS(any_value(), o.use_junction_points, o.use_endpoint_points);
  visit_fields(o.junctions, prefixed("junctions_", visit));
  // The sigmas and losses are set from the scales and thresholds above.
  visit_fields(o.refinement, prefixed("refinement_", visit,
                                      {"point_sigma_px", "line_vp_sigma_px", "vp_sigma_deg",
                                       "point_loss_px", "line_vp_loss_px", "vp_loss_deg"}));
  visit_fields(o.scales, prefixed("scales_", visit));
  visit_fields(o.covariance, prefixed("covariance_", visit));
  HYBRID_VO_FIELDS(non_negative(), o.vp_prior_gate_chi2, o.min_point_inliers);
}

// The paper's table rows: "5pc", "5pc+junc", "5pc+4pc", "5pc+4pc+junc", "hybrid", "hybrid+junc".
bool preset_options(const std::string& preset, RelativePoseEstimatorOptions* options);
const std::vector<std::string>& preset_names();

enum class EstimationStatus {
  kOk,
  kInvalidInput,    // a camera is not invertible
  kTooLittleData,   // no enabled solver can draw a sample from the valid data
  kDegenerate,      // samples were drawn but no solver produced a pose
  kNoModel,         // poses were produced but none has enough support
};
const char* to_string(EstimationStatus status);

struct SolverStatistics {
  int sampled = 0;   // iterations that drew this solver
  int models = 0;    // poses it produced and that were scored
  int best = 0;      // times one of its poses became the best model
};

struct RelativePoseEstimate {
  EstimationStatus status = EstimationStatus::kTooLittleData;
  RelativePose pose;  // unit t; identity/zero unless status == kOk
  // Of [w, t]: w (3, rad) the left rotation increment R <- exp([w]x) R, t (3) the unit
  // translation (rank 5). The pair's honest covariance (pair_covariance.h); the refinement's own,
  // sigma^2 (J^T J)^-1, is hessian_covariance, and the spread of the competing rotations that
  // widened it rotation_spread (rad^2).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_valid = false;
  Eigen::Matrix<double, 6, 6> hessian_covariance = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix3d rotation_spread = Eigen::Matrix3d::Zero();

  // Inlier masks per data type, aligned with the inputs and the derived lists below.
  std::vector<char> point_inliers, line_inliers, vp_inliers;
  std::vector<DerivedPoint> junctions, endpoints;
  std::vector<char> junction_inliers, endpoint_inliers;
  int num_point_inliers = 0, num_line_inliers = 0, num_vp_inliers = 0;
  int num_junction_inliers = 0, num_endpoint_inliers = 0;

  // The noise of each modality, measured on the best model's inliers; the refinement's sigmas.
  ModalityScales scales;
  // Per input VP match: the gate's squared Mahalanobis distance of its prior (NaN without a
  // prior or when the VP is not an inlier) and whether the refinement used the prior.
  std::vector<double> vp_prior_chi2;
  std::vector<char> vp_prior_used;

  std::array<SolverStatistics, kNumSolvers> solvers{};
  SolverId best_solver = SolverId::k5pt;
  int iterations = 0;
  int local_optimizations = 0;
  // Invalid inputs (non-finite, zero-length, bad VP labels) skipped before estimation.
  int rejected_points = 0, rejected_lines = 0, rejected_vps = 0;
  double derive_ms = 0.0, ransac_ms = 0.0, refine_ms = 0.0, total_ms = 0.0;
  bool refined = false;
};

// Relative pose between two calibrated views from points, segments and VPs (paper Sec. 4).
// Everything is in pixels with each camera's intrinsics; the pose maps camera-1 coordinates to
// camera-2 coordinates with a unit translation.
RelativePoseEstimate estimate_relative_pose(const PinholeCamera& camera1,
                                            const PinholeCamera& camera2,
                                            const TwoViewMatches& matches,
                                            const RelativePoseEstimatorOptions& options = {});

}  // namespace hybrid_vo
