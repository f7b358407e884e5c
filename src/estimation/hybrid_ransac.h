#pragma once

// Internal: the hybrid RANSAC loop (paper Sec. 4; Camposeco et al. 2018).

#include <array>
#include <random>
#include <vector>

#include "hybrid_problem.h"
#include "hybrid_vo/estimation/pair_covariance.h"
#include "hybrid_vo/estimation/relative_pose_estimator.h"

namespace hybrid_vo {

struct HybridRansacOutcome {
  bool any_solver_available = false;
  bool any_model = false;
  RelativePose best;
  double best_cost = INFINITY;
  SolverId best_solver = SolverId::k5pt;
  int iterations = 0;
  int local_optimizations = 0;
  std::array<SolverStatistics, kNumSolvers> solvers{};
  // The minimal-sample hypotheses whose cost came within `near_best_margin` of the best cost
  // (the final best's), at most `max_near_best` of the cheapest: the models the data could not
  // rule out (pair_covariance.h).
  std::vector<PoseHypothesis> near_best;
};

HybridRansacOutcome run_hybrid_ransac(const HybridProblem& problem,
                                      const HybridRansacOptions& options, std::mt19937_64* rng,
                                      double near_best_margin = 0.0, int max_near_best = 0);

}  // namespace hybrid_vo
