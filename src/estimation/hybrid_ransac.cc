#include "hybrid_ransac.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "hybrid_vo/estimation/refine_relative_pose.h"
#include "minimal_sampler.h"
#include "model_scorer.h"

namespace hybrid_vo {
namespace {

constexpr double kDegree = M_PI / 180.0;

// Probability that a sample of this solver is all-inlier under the current ratio estimates.
double all_inlier_probability(const SolverInfo& info, double points, double lines, double vps) {
  return std::pow(points, info.num_points) * std::pow(lines, info.num_lines) *
         std::pow(vps, info.num_vps);
}

class LocalOptimizer {
 public:
  LocalOptimizer(const HybridProblem& problem, const ModelScorer& scorer,
                 const HybridRansacOptions& options, std::mt19937_64* rng)
      : problem_(problem), scorer_(scorer), options_(options), rng_(rng) {
    const double focal = 0.5 * (problem.camera1.mean_focal() + problem.camera2.mean_focal());
    refinement_.max_iterations = 10;
    refinement_.loss_scale = options.point_threshold_px / focal;
    // A VP at its threshold weighs like a point at its threshold, once per row (ModelScorer).
    refinement_.vp_weight = refinement_.loss_scale / (options.vp_threshold_deg * kDegree) *
                            std::sqrt(ModelScorer::kVpRows);
  }

  // Refines `pose` on (a subset of) its inliers under `widen` times the threshold; true with `cost`
  // updated when that lowers the cost. A wider first selection lets a model found from a noisy
  // sample reach inliers just outside the threshold (Lebeda et al. 2012, iterated LO).
  bool improve(RelativePose* pose, double* cost, double widen) {
    scorer_.pool_inliers(*pose, &mask_, widen);
    indices_.clear();
    for (int i = 0; i < problem_.num_pool(); ++i)
      if (mask_[i]) indices_.push_back(i);
    if (static_cast<int>(indices_.size()) > options_.lo_max_points) {
      std::shuffle(indices_.begin(), indices_.end(), *rng_);
      indices_.resize(options_.lo_max_points);
    }
    x1_.clear();
    x2_.clear();
    for (int i : indices_) {
      x1_.push_back(problem_.n1[i]);
      x2_.push_back(problem_.n2[i]);
    }
    scorer_.vp_inliers(*pose, &mask_);
    v1_.clear();
    v2_.clear();
    for (int k = 0; k < problem_.num_vps(); ++k) {
      if (!mask_[k]) continue;
      v1_.push_back(problem_.d1[k]);
      v2_.push_back(problem_.d2[k]);
    }
    RelativePose candidate = *pose;
    RelativePoseRefinementOptions refinement = refinement_;
    refinement.loss_scale *= widen;
    refine_relative_pose(x1_, x2_, v1_, v2_, refinement, &candidate);
    const double candidate_cost = scorer_.cost(candidate, *cost);
    if (!(candidate_cost < *cost)) return false;
    *pose = candidate;
    *cost = candidate_cost;
    return true;
  }

 private:
  const HybridProblem& problem_;
  const ModelScorer& scorer_;
  const HybridRansacOptions& options_;
  std::mt19937_64* rng_;
  RelativePoseRefinementOptions refinement_;
  std::vector<char> mask_;
  std::vector<int> indices_;
  std::vector<Eigen::Vector2d> x1_, x2_;
  std::vector<Eigen::Vector3d> v1_, v2_;
};

// Keeps the hypotheses within `margin` of `best`, at most `cap` of the cheapest.
void prune_near_best(double best, double margin, size_t cap, std::vector<PoseHypothesis>* kept) {
  kept->erase(std::remove_if(kept->begin(), kept->end(),
                             [&](const PoseHypothesis& h) { return !(h.cost < best + margin); }),
              kept->end());
  if (kept->size() <= cap) return;
  std::nth_element(kept->begin(), kept->begin() + cap, kept->end(),
                   [](const PoseHypothesis& a, const PoseHypothesis& b) { return a.cost < b.cost; });
  kept->resize(cap);
}

}  // namespace

HybridRansacOutcome run_hybrid_ransac(const HybridProblem& problem,
                                      const HybridRansacOptions& options, std::mt19937_64* rng,
                                      double near_best_margin, int max_near_best) {
  HybridRansacOutcome out;
  const bool keep = near_best_margin > 0.0 && max_near_best > 0;
  const size_t cap = static_cast<size_t>(std::max(0, max_near_best));
  MinimalSampler sampler(problem, rng);
  const ModelScorer scorer(problem, options.point_threshold_px, options.vp_threshold_deg * kDegree);
  LocalOptimizer optimizer(problem, scorer, options, rng);

  std::vector<int> active;
  for (const SolverInfo& info : solver_table()) {
    const int s = static_cast<int>(info.id);
    if (options.enabled[s] && info.well_posed && options.prior[s] > 0.0 && sampler.available(info.id))
      active.push_back(s);
  }
  out.any_solver_available = !active.empty();
  if (active.empty()) return out;

  // Selection follows the paper: prior * P(all-inlier sample) with the line ratio preset, mixed
  // with a uniform share so that one wrong best model (whose measured ratios starve the other
  // solvers, e.g. every VP an outlier) cannot stop the others from being tried. Termination is
  // stricter: it uses the measured line support, a lower bound, because a preset ratio would let
  // line-only solvers end the search after a few dozen draws whatever the data.
  double point_ratio = options.initial_point_inlier_ratio;
  double vp_ratio = options.initial_vp_inlier_ratio;
  double measured_line_ratio = options.line_inlier_ratio;
  const double exploration = std::clamp(options.exploration, 0.0, 1.0);
  std::vector<double> selection(kNumSolvers, 0.0), termination(kNumSolvers, 0.0);
  std::vector<double> cumulative(active.size());
  auto refresh = [&]() {
    double adaptive_total = 0.0;
    for (int s : active) {
      const SolverInfo& info = solver_table()[s];
      selection[s] = options.prior[s] * all_inlier_probability(info, point_ratio,
                                                                options.line_inlier_ratio, vp_ratio);
      adaptive_total += selection[s];
      termination[s] = std::clamp(
          all_inlier_probability(info, point_ratio, measured_line_ratio, vp_ratio), 1e-300,
          1.0 - 1e-12);
    }
    double total = 0.0;
    for (size_t a = 0; a < active.size(); ++a) {
      const double adaptive = adaptive_total > 0.0 ? selection[active[a]] / adaptive_total : 0.0;
      total += (1.0 - exploration) * adaptive + exploration / active.size();
      cumulative[a] = total;
    }
  };
  refresh();
  const bool reserve_five_point =
      active.size() > 1 && std::find(active.begin(), active.end(),
                                     static_cast<int>(SolverId::k5pt)) != active.end();
  const double five_point_share = std::clamp(options.five_point_share, 0.0, 1.0);
  const int valid_lines = static_cast<int>(
      std::count(problem.line_valid.begin(), problem.line_valid.end(), static_cast<char>(1)));

  const double log_miss_target = std::log(1.0 - std::clamp(options.confidence, 0.0, 1.0 - 1e-15));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<int> drawn(kNumSolvers, 0);  // samples actually drawn, for the termination test
  // A homography solver's all-inlier sample gives the right pose only when its points and lines
  // lie on one plane, which no inlier ratio predicts; counted like the others, its cheap samples
  // ended the search early in scenes that are not planar (TUM gap 3, 40 runs: 5pc+4pc -2.90
  // against 5pc, -0.96 without them). So its draws count only when nothing else is enabled.
  std::vector<char> counts_for_termination(kNumSolvers, 1);
  bool any_general = false;
  for (int s : active) any_general |= !solver_table()[s].coplanar;
  for (int s : active) counts_for_termination[s] = !any_general || !solver_table()[s].coplanar;
  MinimalSample sample;
  RelativePoses poses;
  poses.reserve(32);

  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    if (iteration >= options.min_iterations && out.any_model) {
      // Camposeco et al.: the chance that no draw so far was all-inlier, over every solver
      // whose draws count.
      double log_miss = 0.0;
      for (int s : active)
        if (counts_for_termination[s]) log_miss += drawn[s] * std::log1p(-termination[s]);
      if (log_miss <= log_miss_target) break;
    }
    out.iterations = iteration + 1;
    int s = static_cast<int>(SolverId::k5pt);
    if (!reserve_five_point || !(unit(*rng) < five_point_share)) {
      const double r = unit(*rng) * cumulative.back();
      const size_t a = std::min<size_t>(
          std::lower_bound(cumulative.begin(), cumulative.end(), r) - cumulative.begin(),
          active.size() - 1);
      s = active[a];
    }
    out.solvers[s].sampled++;
    if (!sampler.draw(static_cast<SolverId>(s), &sample)) continue;
    drawn[s]++;
    solve_minimal(static_cast<SolverId>(s), sample, &poses);
    bool improved = false;
    for (const RelativePose& pose : poses) {
      if (!(pose.t.squaredNorm() > 0.0)) continue;  // pure rotation: no epipolar geometry to score
      out.solvers[s].models++;
      out.any_model = true;
      // Scored to the margin only when hypotheses are kept: the early exit at the best cost is
      // what makes scoring cheap.
      const double cost = scorer.cost(pose, out.best_cost + (keep ? near_best_margin : 0.0));
      if (keep && cost < out.best_cost + near_best_margin) {
        out.near_best.push_back({pose.R, cost, pose.t});
        if (out.near_best.size() >= 2 * cap) prune_near_best(out.best_cost, near_best_margin, cap, &out.near_best);
      }
      if (cost < out.best_cost) {
        out.best_cost = cost;
        out.best = pose;
        out.best_solver = static_cast<SolverId>(s);
        improved = true;
      }
    }
    if (!improved) continue;
    out.solvers[s].best++;
    if (options.local_optimization) {
      // Iterated with a shrinking threshold: each refinement can gain inliers the next one uses.
      for (int round = 0; round < options.lo_rounds; ++round) {
        ++out.local_optimizations;
        const double widen = std::max(1.0, 3.0 - round);
        if (!optimizer.improve(&out.best, &out.best_cost, widen) && widen == 1.0) break;
      }
    }
    std::vector<char> mask;
    const int pool_inliers = scorer.pool_inliers(out.best, &mask);
    if (problem.num_pool() > 0)
      point_ratio = std::max(1e-3, static_cast<double>(pool_inliers) / problem.num_pool());
    if (problem.num_vps() > 0)
      vp_ratio = std::max(1e-3, static_cast<double>(scorer.vp_inliers(out.best, &mask)) /
                                    problem.num_vps());
    if (valid_lines > 0)
      measured_line_ratio =
          std::max(1e-3, static_cast<double>(scorer.line_support(out.best)) / valid_lines);
    refresh();
  }
  if (keep) prune_near_best(out.best_cost, near_best_margin, cap, &out.near_best);
  return out;
}

}  // namespace hybrid_vo
