#include "hybrid_vo/estimation/relative_pose_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>

#include "hybrid_problem.h"
#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/geometry/vp_covariance.h"
#include "hybrid_vo/geometry/vp_distance.h"
#include "hybrid_ransac.h"
#include "model_scorer.h"

namespace hybrid_vo {
namespace {

constexpr double kDegree = M_PI / 180.0;

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Inlier masks of every data type for the estimate's pose.
void fill_inliers(const HybridProblem& problem, const ModelScorer& scorer,
                  const RelativePoseEstimatorOptions& options, const TwoViewMatches& matches,
                  RelativePoseEstimate* est) {
  std::vector<char> pool, vps;
  scorer.pool_inliers(est->pose, &pool);
  scorer.vp_inliers(est->pose, &vps);
  est->point_inliers.assign(matches.points.size(), 0);
  est->junction_inliers.assign(est->junctions.size(), 0);
  est->endpoint_inliers.assign(est->endpoints.size(), 0);
  for (int i = 0; i < problem.num_pool(); ++i)
    if (problem.origin[i].source == PointSource::kPoint) est->point_inliers[problem.origin[i].first] = pool[i];
  // Junctions and endpoints are scored even when they were not in the pool.
  const Eigen::Matrix3d F = scorer.fundamental(est->pose);
  const double threshold_sq = options.ransac.point_threshold_px * options.ransac.point_threshold_px;
  for (size_t j = 0; j < est->junctions.size(); ++j) {
    const PointMatch& m = est->junctions[j].match;
    est->junction_inliers[j] = scorer.squared_sampson(F, m.x1, m.x2) <= threshold_sq;
  }
  for (size_t j = 0; j < est->endpoints.size(); ++j) {
    const PointMatch& m = est->endpoints[j].match;
    est->endpoint_inliers[j] = scorer.squared_sampson(F, m.x1, m.x2) <= threshold_sq;
  }

  est->vp_inliers.assign(matches.vps.size(), 0);
  for (int k = 0; k < problem.num_vps(); ++k) est->vp_inliers[problem.vp_index[k]] = vps[k];

  // A line is an inlier when it meets another line at an inlier junction, or when it agrees with
  // the rotation through its VP label. Nothing else about a single line is observable.
  scorer.line_support(est->pose, &est->line_inliers);

  auto count = [](const std::vector<char>& m) {
    int n = 0;
    for (char c : m) n += c != 0;
    return n;
  };
  est->num_point_inliers = count(est->point_inliers);
  est->num_line_inliers = count(est->line_inliers);
  est->num_vp_inliers = count(est->vp_inliers);
  est->num_junction_inliers = count(est->junction_inliers);
  est->num_endpoint_inliers = count(est->endpoint_inliers);
}

void orient_by_inliers(const HybridProblem& problem, const ModelScorer& scorer, RelativePose* pose) {
  std::vector<char> pool;
  scorer.pool_inliers(*pose, &pool);
  std::vector<Eigen::Vector2d> x1, x2;
  for (int i = 0; i < problem.num_pool(); ++i) {
    if (!pool[i]) continue;
    x1.push_back(problem.n1[i]);
    x2.push_back(problem.n2[i]);
  }
  MatchView view;
  view.x1 = x1.data();
  view.x2 = x2.data();
  view.num_points = static_cast<int>(x1.size());
  orient_translation_by_majority(pose->R, &pose->t, view);
}

// The noise scale of every modality from its residuals under `pose` (ModalityScales).
ModalityScales measure_scales(const HybridProblem& problem, const ModelScorer& scorer,
                              const RelativePoseEstimatorOptions& options,
                              const TwoViewMatches& matches, const RelativePose& pose) {
  const ModalityScaleOptions& o = options.scales;
  const double point_gate = o.inlier_multiple * options.ransac.point_threshold_px;
  const double vp_gate = options.ransac.vp_threshold_deg * kDegree;
  const double line_gate = o.inlier_multiple * o.line_threshold_px;
  ModalityScales scales;
  scales.point_px = scales.junction_px = o.default_fraction * options.ransac.point_threshold_px;
  scales.line_vp_px = o.default_fraction * o.line_threshold_px;
  scales.vp_deg = o.default_fraction * options.ransac.vp_threshold_deg;
  if (!o.enabled) return scales;

  std::vector<double> points, junctions, lines, vps;
  const Eigen::Matrix3d F = scorer.fundamental(pose);
  for (int i = 0; i < problem.num_pool(); ++i) {
    if (problem.origin[i].source != PointSource::kPoint) continue;
    const double r = std::sqrt(scorer.squared_sampson(F, i));
    if (r <= point_gate) points.push_back(r);
  }
  for (size_t j = 0; j < problem.junction_px1.size(); ++j) {
    const double r =
        std::sqrt(scorer.squared_sampson(F, problem.junction_px1[j], problem.junction_px2[j]));
    if (r <= point_gate) junctions.push_back(r);
  }
  // VPs within the VP threshold (a wrong VP is not a noisy one), and their labelled segments
  // against the detected VP in each image.
  std::vector<char> vp_inlier(problem.num_vps(), 0);
  for (int k = 0; k < problem.num_vps(); ++k) {
    const double a = scorer.vp_angle(pose.R, k);
    if (a <= vp_gate) {
      vps.push_back(a);
      vp_inlier[k] = 1;
    }
  }
  const Eigen::Matrix3d K1 = problem.camera1.K(), K2 = problem.camera2.K();
  for (int i = 0; i < problem.num_lines(); ++i) {
    const int k = problem.line_vp[i];
    if (k < 0 || !vp_inlier[k] || !problem.line_valid[i]) continue;
    const LineMatch& m = matches.lines[i];
    for (const double r : {tardif_distance(m.s1, K1 * problem.d1[k]),
                           tardif_distance(m.s2, K2 * problem.d2[k])})
      if (r <= line_gate) lines.push_back(r);
  }
  if (static_cast<int>(points.size()) >= o.min_points) {
    scales.num_points = static_cast<int>(points.size());
    scales.point_px = std::max(o.min_point_px, robust_sigma(&points, 1));
    scales.junction_px = scales.point_px;
  }
  if (static_cast<int>(junctions.size()) >= o.min_junctions) {
    scales.num_junctions = static_cast<int>(junctions.size());
    scales.junction_px = std::max(o.min_point_px, robust_sigma(&junctions, 1));
  }
  if (static_cast<int>(lines.size()) >= o.min_lines) {
    scales.num_lines = static_cast<int>(lines.size());
    scales.line_vp_px = std::max(o.min_line_px, robust_sigma(&lines, 1));
  }
  if (static_cast<int>(vps.size()) >= o.min_vps) {
    scales.num_vps = static_cast<int>(vps.size());
    scales.vp_deg = std::max(o.min_vp_deg, robust_sigma(&vps, 2) / kDegree);
  }
  return scales;
}

// The gate of a VP prior (RelativePoseEstimatorOptions::vp_prior_gate_chi2): the prior's
// direction carried into camera 2 by the pair's rotation against the VP seen there, under the
// prior's covariance, the rotation's, and that of image 2's VP: the VP scale and its fit to its
// segments.
double vp_prior_chi2(const HybridProblem& problem, const TwoViewMatches& matches,
                     const ModalityScales& scales, const RelativePose& pose,
                     const Eigen::Matrix3d& rotation_covariance, int k) {
  const VpPrior& prior = matches.vp_priors[problem.vp_index[k]];
  const Eigen::Vector3d predicted = pose.R * prior.direction.normalized();
  std::vector<LineSegment> segments;
  for (int i = 0; i < problem.num_lines(); ++i)
    if (problem.line_vp[i] == k && problem.line_valid[i]) segments.push_back(matches.lines[i].s2);
  const Eigen::Vector3d& d2 = problem.d2[k];
  // The pair's VP scale, measured under this rotation, adds what the segments' fit does not see,
  // and the rotation's own error with it.
  Eigen::Matrix3d observed;
  vp_measurement_covariance(problem.camera2.K(), segments, d2, scales.line_vp_px,
                            scales.vp_deg * kDegree, &observed);
  // The prior carried into camera 2, with the rotation's own uncertainty: a left increment w
  // moves R p by -[R p]x w.
  const Eigen::Matrix3d J = -skew(predicted);
  const Eigen::Matrix3d carried = pose.R * prior.covariance * pose.R.transpose() +
                                  J * rotation_covariance * J.transpose();
  return direction_chi2(predicted, d2, carried + observed,
                        static_cast<bool>(problem.vp_sign_known[k]));
}

// The spread of RANSAC's competing rotations about R, `points` point-like matches of the
// estimate's measured noise (pair_covariance.h).
Eigen::Matrix3d competing_spread(const HybridRansacOutcome& outcome, const Eigen::Matrix3d& R,
                                 double points, const RelativePoseEstimate& est,
                                 const RelativePoseEstimatorOptions& options) {
  return rotation_spread(
      outcome.near_best, R, outcome.best_cost,
      hypothesis_temperature(points, options.covariance.ambiguity_independent_points,
                             est.scales.point_px, options.ransac.point_threshold_px));
}

// Ceres refinement on the inliers (paper Sec. 4, final step), every residual weighted by its
// modality's measured scale; kept unless it loses inliers. Then the VP priors: each is gated
// against the rotation this pair's own data support (the refined pose and its covariance), and
// those that pass pull a second refinement, which starts from the first.
void refine_final(const HybridProblem& problem, const ModelScorer& scorer,
                  const RelativePoseEstimatorOptions& options, const TwoViewMatches& matches,
                  const HybridRansacOutcome& outcome, RelativePoseEstimate* est,
                  InformationSplit* split) {
  std::vector<char> pool, vps;
  const int pool_before = scorer.pool_inliers(est->pose, &pool);
  scorer.vp_inliers(est->pose, &vps);
  RefinementData data;
  for (int i = 0; i < problem.num_pool(); ++i) {
    if (!pool[i]) continue;
    data.points.push_back({problem.px1[i], problem.px2[i]});
    data.point_sigma_px.push_back(problem.origin[i].source == PointSource::kPoint
                                      ? est->scales.point_px
                                      : est->scales.junction_px);
  }
  std::vector<int> refined_index(problem.num_vps(), -1), internal_index;
  for (int k = 0; k < problem.num_vps(); ++k) {
    if (!vps[k]) continue;
    refined_index[k] = static_cast<int>(data.vps.size());
    internal_index.push_back(k);
    data.vps.push_back({problem.d1[k], problem.d2[k], static_cast<bool>(problem.vp_sign_known[k])});
  }
  for (int i = 0; i < problem.num_lines(); ++i) {
    const int k = problem.line_vp[i];
    if (k < 0 || refined_index[k] < 0) continue;
    data.lines.push_back(matches.lines[i]);
    data.line_vp.push_back(refined_index[k]);
  }
  FinalRefinementOptions refinement = options.refinement;
  refinement.point_sigma_px = est->scales.point_px;
  refinement.line_vp_sigma_px = est->scales.line_vp_px;
  refinement.vp_sigma_deg = est->scales.vp_deg;
  // Outliers are what RANSAC called outliers, whatever the measured noise.
  refinement.point_loss_px = options.ransac.point_threshold_px;
  refinement.line_vp_loss_px = options.scales.line_threshold_px;
  refinement.vp_loss_deg = options.ransac.vp_threshold_deg;
  // A refinement is kept unless it loses inliers: 5 % without priors; with priors that passed
  // their gate, half (a gated prior may correct a RANSAC model that fits the points wrongly,
  // e.g. a rotation-translation confusion, and then moves it by more than the threshold).
  auto accept = [&](const FinalRefinementResult& r, double keep) {
    std::vector<char> after;
    if (!r.success || scorer.pool_inliers(r.pose, &after) < keep * pool_before) return false;
    est->pose = r.pose;
    est->covariance = r.covariance;
    est->covariance_valid = r.covariance_valid;
    *split = r.split;
    est->refined = true;
    return true;
  };
  const FinalRefinementResult first =
      refine_relative_pose_ceres(problem.camera1, problem.camera2, data, est->pose, refinement);
  if (!accept(first, 0.95) && first.success && first.covariance_valid) {
    // The data's optimum lost inliers and the RANSAC model stays: its covariance is the
    // optimum's curvature, widened by how far the model lies from it.
    est->covariance = first.covariance;
    const Eigen::AngleAxisd apart(Eigen::Matrix3d(first.pose.R * est->pose.R.transpose()));
    const Eigen::Vector3d w = apart.angle() * apart.axis();
    est->covariance.topLeftCorner<3, 3>() += w * w.transpose();
    est->covariance_valid = all_finite(est->covariance);
    *split = first.split;
  }

  if (matches.vp_priors.size() != matches.vps.size() || data.vps.empty()) return;
  // Against a prior, which carries many frames, the pair's points weigh what they know: their
  // rotation's variance as the pair reports it (pair_covariance.h: the points counted as
  // independent_points, the spread of the competing rotations added) over what their residuals
  // say, in the gate (their rotation's covariance) and in the refinement with the priors. Where
  // the split is missing, they count as at most max_independent_points matches. A pair alone (no
  // prior) keeps the measured sigmas.
  double dependence = std::sqrt(
      std::max(1.0, static_cast<double>(data.points.size()) /
                        std::max(1.0, options.scales.max_independent_points)));
  const PairCovarianceOptions& honest = options.covariance;
  if (honest.enabled && split->valid) {
    const double n = static_cast<double>(data.points.size());
    const Eigen::Matrix3d own = split->points_covariance.topLeftCorner<3, 3>();
    const Eigen::Matrix3d weighed = std::max(1.0, n / honest.independent_points) * own +
                                    competing_spread(outcome, est->pose.R, n, *est, options);
    if (own.trace() > 0.0 && all_finite(weighed))
      dependence = std::sqrt(std::max(1.0, weighed.trace() / own.trace()));
  }
  for (double& sigma : data.point_sigma_px) sigma *= dependence;
  est->scales.point_dependence = dependence;
  data.vp_priors.assign(data.vps.size(), VpPrior());
  bool any = false;
  const Eigen::Matrix3d rotation_covariance =
      est->covariance_valid
          ? Eigen::Matrix3d(dependence * dependence * est->covariance.topLeftCorner<3, 3>())
          : Eigen::Matrix3d::Zero();
  for (size_t j = 0; j < data.vps.size(); ++j) {
    const int k = internal_index[j];
    const int input = problem.vp_index[k];
    if (!matches.vp_priors[input].valid) continue;
    const double chi2 =
        vp_prior_chi2(problem, matches, est->scales, est->pose, rotation_covariance, k);
    est->vp_prior_chi2[input] = chi2;
    if (!(chi2 <= options.vp_prior_gate_chi2)) continue;
    data.vp_priors[j] = matches.vp_priors[input];
    est->vp_prior_used[input] = 1;
    any = true;
  }
  // The VPs without a prior are the pair's own evidence, like its points: weakened alike, they
  // keep the balance of the first refinement. The segments of a VP with a prior carry it into
  // the rotation and keep their sigma (weakened too, they cost the rendered corridor 2.3 -> 10.7
  // deg/100 m; doc/vanishing_points.md).
  data.vp_sigma_scale.assign(data.vps.size(), 1.0);
  for (size_t j = 0; j < data.vps.size(); ++j)
    if (!data.vp_priors[j].valid) data.vp_sigma_scale[j] = dependence;
  if (any && !accept(refine_relative_pose_ceres(problem.camera1, problem.camera2, data, est->pose,
                                                refinement),
                     0.5))
    std::fill(est->vp_prior_used.begin(), est->vp_prior_used.end(), 0);
}

}  // namespace

HybridRansacOptions::HybridRansacOptions() {
  enabled.fill(true);
  enabled[static_cast<int>(SolverId::kHomography2pt2l)] = false;
  prior.fill(1.0);
}

const std::vector<std::string>& preset_names() {
  static const std::vector<std::string> names = {"5pc",    "5pc+junc", "5pc+4pc", "5pc+4pc+junc",
                                                 "hybrid", "hybrid+junc"};
  return names;
}

bool preset_options(const std::string& preset, RelativePoseEstimatorOptions* options) {
  const bool junc = preset.size() > 5 && preset.compare(preset.size() - 5, 5, "+junc") == 0;
  const std::string base = junc ? preset.substr(0, preset.size() - 5) : preset;
  std::array<bool, kNumSolvers> enabled{};
  if (base == "5pc") {
    enabled[static_cast<int>(SolverId::k5pt)] = true;
  } else if (base == "5pc+4pc") {
    enabled[static_cast<int>(SolverId::k5pt)] = true;
    enabled[static_cast<int>(SolverId::kHomography4pt)] = true;
  } else if (base == "hybrid") {
    for (const SolverInfo& info : solver_table()) enabled[static_cast<int>(info.id)] = info.well_posed;
  } else {
    return false;
  }
  options->ransac.enabled = enabled;
  options->use_junction_points = junc;
  return true;
}

const char* to_string(EstimationStatus status) {
  switch (status) {
    case EstimationStatus::kOk:
      return "ok";
    case EstimationStatus::kInvalidInput:
      return "invalid input";
    case EstimationStatus::kTooLittleData:
      return "too little data";
    case EstimationStatus::kDegenerate:
      return "degenerate";
    case EstimationStatus::kNoModel:
      return "no model";
  }
  return "unknown";
}

RelativePoseEstimate estimate_relative_pose(const PinholeCamera& camera1,
                                            const PinholeCamera& camera2,
                                            const TwoViewMatches& matches,
                                            const RelativePoseEstimatorOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  RelativePoseEstimate est;
  auto finish = [&](EstimationStatus status) {
    est.status = status;
    if (status != EstimationStatus::kOk) {
      est.pose = RelativePose();
      est.point_inliers.assign(matches.points.size(), 0);
      est.line_inliers.assign(matches.lines.size(), 0);
      est.vp_inliers.assign(matches.vps.size(), 0);
      est.junction_inliers.assign(est.junctions.size(), 0);
      est.endpoint_inliers.assign(est.endpoints.size(), 0);
      est.num_point_inliers = est.num_line_inliers = est.num_vp_inliers = 0;
      est.num_junction_inliers = est.num_endpoint_inliers = 0;
      est.covariance.setZero();
      est.covariance_valid = false;
    }
    est.total_ms = ms_since(start);
    return est;
  };
  est.vp_prior_chi2.assign(matches.vps.size(), std::numeric_limits<double>::quiet_NaN());
  est.vp_prior_used.assign(matches.vps.size(), 0);
  if (!camera1.valid() || !camera2.valid()) return finish(EstimationStatus::kInvalidInput);

  // A preset only sees the data its solvers use, so that point-only baselines stay point-only in
  // scoring and refinement too (the paper's 5pc rows use no VPs or lines).
  HybridProblemOptions problem_options;
  problem_options.use_vps = problem_options.use_lines = false;
  for (const SolverInfo& info : solver_table()) {
    if (!options.ransac.enabled[static_cast<int>(info.id)]) continue;
    problem_options.use_vps = problem_options.use_vps || info.num_vps > 0;
    problem_options.use_lines = problem_options.use_lines || info.num_lines > 0 || info.orthogonal;
  }
  problem_options.junction_points = options.use_junction_points;
  problem_options.endpoint_points = options.use_endpoint_points;
  problem_options.junctions = options.junctions;
  problem_options.orthogonal_tolerance_deg = options.ransac.orthogonal_tolerance_deg;
  RejectedInputs rejected;
  const HybridProblem problem = build_hybrid_problem(camera1, camera2, matches, problem_options,
                                                     &est.junctions, &est.endpoints, &rejected);
  est.rejected_points = rejected.points;
  est.rejected_lines = rejected.lines;
  est.rejected_vps = rejected.vps;
  est.derive_ms = ms_since(start);

  const auto ransac_start = std::chrono::steady_clock::now();
  std::mt19937_64 rng(options.ransac.seed);
  const PairCovarianceOptions& honest = options.covariance;
  const HybridRansacOutcome outcome =
      run_hybrid_ransac(problem, options.ransac, &rng,
                        honest.enabled ? honest.hypothesis_margin : 0.0, honest.max_hypotheses);
  est.ransac_ms = ms_since(ransac_start);
  est.solvers = outcome.solvers;
  est.iterations = outcome.iterations;
  est.local_optimizations = outcome.local_optimizations;
  est.best_solver = outcome.best_solver;
  if (!outcome.any_solver_available) return finish(EstimationStatus::kTooLittleData);
  if (!outcome.any_model) return finish(EstimationStatus::kDegenerate);

  est.pose = outcome.best;
  const ModelScorer scorer(problem, options.ransac.point_threshold_px,
                           options.ransac.vp_threshold_deg * kDegree);
  std::vector<char> pool;
  if (scorer.pool_inliers(est.pose, &pool) < options.min_point_inliers)
    return finish(EstimationStatus::kNoModel);

  est.scales = measure_scales(problem, scorer, options, matches, est.pose);
  InformationSplit split;
  if (options.refinement.enabled) {
    const auto refine_start = std::chrono::steady_clock::now();
    refine_final(problem, scorer, options, matches, outcome, &est, &split);
    est.refine_ms = ms_since(refine_start);
  }
  // The split's tangent is that of the refined t, before its sign is chosen.
  const Eigen::Vector3d refined_t = est.pose.t;
  // The Sampson error cannot tell t from -t, and the minimal sample that fixed the sign was
  // tiny: the inliers vote on it (depths in front of both cameras).
  orient_by_inliers(problem, scorer, &est.pose);
  fill_inliers(problem, scorer, options, matches, &est);
  est.hessian_covariance = est.covariance;
  if (honest.enabled && est.covariance_valid) {
    const double point_matches = est.num_point_inliers + est.num_junction_inliers;
    est.rotation_spread = competing_spread(outcome, est.pose.R, point_matches, est, options);
    const Eigen::Matrix<double, 5, 5> spread = pose_spread(
        outcome.near_best, est.pose.R, refined_t, split.to_pose.bottomRightCorner<3, 2>(),
        outcome.best_cost,
        hypothesis_temperature(point_matches, honest.ambiguity_independent_points,
                               est.scales.point_px, options.ransac.point_threshold_px));
    if (!pair_covariance(split, spread, point_matches, est.num_line_inliers, honest,
                         &est.covariance)) {
      // The points alone do not fix the pose (too few, or VPs carry it): the refinement's
      // covariance, its segments counted as independent_segments, and the spread.
      est.covariance =
          std::max(1.0, est.num_line_inliers / honest.independent_segments) * est.hessian_covariance;
      est.covariance.topLeftCorner<3, 3>() += est.rotation_spread;
    }
    const double shared = honest.shared_error_px / camera2.mean_focal();
    est.covariance.topLeftCorner<3, 3>() += shared * shared * Eigen::Matrix3d::Identity();
    // The translation's points count as fewer (pair_covariance.h): its correlations scaled too.
    const double extra = std::sqrt(
        std::max(1.0, point_matches / honest.independent_translation_points) /
        std::max(1.0, point_matches / honest.independent_points));
    est.covariance.bottomRows<3>() *= extra;
    est.covariance.rightCols<3>() *= extra;
  }
  return finish(EstimationStatus::kOk);
}

}  // namespace hybrid_vo
