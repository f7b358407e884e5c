#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/solvers/minimal_solver.h"

namespace hybrid_vo {
namespace testing {

struct BestError {
  double rotation = std::numeric_limits<double>::infinity();
  double translation = std::numeric_limits<double>::infinity();
  double pose() const { return std::max(rotation, translation); }
};

// The solution closest to the truth, by pose error.
inline BestError best_error(const RelativePoses& poses, const RelativePose& truth) {
  BestError best;
  for (const RelativePose& p : poses) {
    const BestError e{rotation_error(p.R, truth.R), translation_error(p.t, truth.t)};
    if (e.pose() < best.pose()) best = e;
  }
  return best;
}

// Every pose is finite, R is a rotation and t is unit (or zero for a pure rotation).
inline bool all_valid(const RelativePoses& poses) {
  for (const RelativePose& p : poses) {
    if (!all_finite(p.R) || !all_finite(p.t)) return false;
    if ((p.R.transpose() * p.R - Eigen::Matrix3d::Identity()).norm() > 1e-6) return false;
    if (std::abs(p.R.determinant() - 1.0) > 1e-6) return false;
    const double n = p.t.norm();
    if (n != 0.0 && std::abs(n - 1.0) > 1e-9) return false;
  }
  return true;
}

inline double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

template <typename Predicate>
std::vector<SolverId> solvers_where(Predicate keep) {
  std::vector<SolverId> ids;
  for (const SolverInfo& info : solver_table())
    if (keep(info)) ids.push_back(info.id);
  return ids;
}

inline std::vector<SolverId> all_solvers() {
  return solvers_where([](const SolverInfo&) { return true; });
}
inline std::vector<SolverId> well_posed_solvers() {
  return solvers_where([](const SolverInfo& i) { return i.well_posed; });
}
inline std::vector<SolverId> vp_solvers() {
  return solvers_where([](const SolverInfo& i) { return i.num_vps > 0; });
}

inline std::string solver_name(const ::testing::TestParamInfo<SolverId>& param) {
  return solver_info(param.param).function;
}

}  // namespace testing
}  // namespace hybrid_vo
