#include "hybrid_vo/estimation/relative_pose_estimator.h"

#include <chrono>
#include <cmath>
#include <random>

#include "hybrid_problem.h"
#include "hybrid_vo/geometry/cheirality.h"
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

// Ceres refinement on the inliers (paper Sec. 4, final step); kept unless it loses inliers.
void refine_final(const HybridProblem& problem, const ModelScorer& scorer,
                  const RelativePoseEstimatorOptions& options, const TwoViewMatches& matches,
                  RelativePoseEstimate* est) {
  std::vector<char> pool, vps;
  const int pool_before = scorer.pool_inliers(est->pose, &pool);
  scorer.vp_inliers(est->pose, &vps);
  std::vector<PointMatch> points;
  for (int i = 0; i < problem.num_pool(); ++i)
    if (pool[i]) points.push_back({problem.px1[i], problem.px2[i]});
  std::vector<VpMatch> inlier_vps;
  std::vector<int> refined_index(problem.num_vps(), -1);
  for (int k = 0; k < problem.num_vps(); ++k) {
    if (!vps[k]) continue;
    refined_index[k] = static_cast<int>(inlier_vps.size());
    inlier_vps.push_back({problem.d1[k], problem.d2[k], static_cast<bool>(problem.vp_sign_known[k])});
  }
  std::vector<LineMatch> lines;
  std::vector<int> line_vp;
  for (int i = 0; i < problem.num_lines(); ++i) {
    const int k = problem.line_vp[i];
    if (k < 0 || refined_index[k] < 0) continue;
    lines.push_back(matches.lines[i]);
    line_vp.push_back(refined_index[k]);
  }
  const FinalRefinementResult r = refine_relative_pose_ceres(
      problem.camera1, problem.camera2, points, inlier_vps, lines, line_vp, est->pose,
      options.refinement);
  if (!r.success) return;
  std::vector<char> after;
  if (scorer.pool_inliers(r.pose, &after) < 0.95 * pool_before) return;
  est->pose = r.pose;
  est->covariance = r.covariance;
  est->covariance_valid = r.covariance_valid;
  est->refined = true;
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
  const HybridRansacOutcome outcome = run_hybrid_ransac(problem, options.ransac, &rng);
  est.ransac_ms = ms_since(ransac_start);
  est.solvers = outcome.solvers;
  est.iterations = outcome.iterations;
  est.local_optimizations = outcome.local_optimizations;
  est.best_solver = outcome.best_solver;
  if (!outcome.any_solver_available) return finish(EstimationStatus::kTooLittleData);
  if (!outcome.any_model) return finish(EstimationStatus::kDegenerate);

  est.pose = outcome.best;
  const ModelScorer scorer(problem, options.ransac.point_threshold_px,
                           options.ransac.vp_threshold_deg * kDegree,
                           options.ransac.vp_score_weight);
  std::vector<char> pool;
  if (scorer.pool_inliers(est.pose, &pool) < options.min_point_inliers)
    return finish(EstimationStatus::kNoModel);

  if (options.final_refinement) {
    const auto refine_start = std::chrono::steady_clock::now();
    refine_final(problem, scorer, options, matches, &est);
    est.refine_ms = ms_since(refine_start);
  }
  // The Sampson error cannot tell t from -t, and the minimal sample that fixed the sign was
  // tiny: the inliers vote on it (depths in front of both cameras).
  orient_by_inliers(problem, scorer, &est.pose);
  fill_inliers(problem, scorer, options, matches, &est);
  return finish(EstimationStatus::kOk);
}

}  // namespace hybrid_vo
