#pragma once

// Internal: the hybrid RANSAC loop (paper Sec. 4; Camposeco et al. 2018).

#include <array>
#include <random>

#include "hybrid_problem.h"
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
};

HybridRansacOutcome run_hybrid_ransac(const HybridProblem& problem,
                                      const HybridRansacOptions& options, std::mt19937_64* rng);

}  // namespace hybrid_vo
