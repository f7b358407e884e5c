#pragma once

// Internal: draws minimal samples that respect each solver's assumptions (issue: lines orthogonal
// to a VP come from another, orthogonal VP's cluster; coplanar line sets are connected by
// junctions; the two points of 2-0-1 lie on one such line).

#include <array>
#include <random>

#include "hybrid_problem.h"
#include "hybrid_vo/solvers/minimal_solver.h"

namespace hybrid_vo {

class MinimalSampler {
 public:
  MinimalSampler(const HybridProblem& problem, std::mt19937_64* rng);

  // Whether the data can feed the solver at all.
  bool available(SolverId id) const { return available_[static_cast<int>(id)]; }
  // Draws a sample; false when this attempt found none (e.g. no suitable neighbour).
  bool draw(SolverId id, MinimalSample* sample);

 private:
  int uniform(int n) { return std::uniform_int_distribution<int>(0, n - 1)(*rng_); }
  bool draw_points(int count, MinimalSample* s, int first_slot = 0);
  // A line with at least `count` junction neighbours and `count` of them: a likely coplanar set.
  bool draw_connected_lines(int count, MinimalSample* s, int exclude_vp = -1);
  void put_line(int line, int slot, MinimalSample* s) const;
  void put_vp(int vp, int slot, MinimalSample* s) const;

  const HybridProblem& problem_;
  std::mt19937_64* rng_;
  std::array<bool, kNumSolvers> available_{};
  std::vector<int> valid_lines_;
  std::vector<int> lines_with_neighbours_[4];  // index k: lines with >= k neighbours (k = 1..3)
  // Orthogonal VP pairs whose second VP has lines (with a neighbour / with two junctions).
  std::vector<std::pair<int, int>> orth_with_lines_, orth_with_connected_, orth_with_points_;
};

}  // namespace hybrid_vo
