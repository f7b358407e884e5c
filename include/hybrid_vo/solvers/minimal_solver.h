#pragma once

#include <array>
#include <string>

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// The thirteen minimal configurations of the paper's Fig. 2, in its order.
enum class SolverId {
  k5pt,              // 5-0-0
  kHomography4pt,    // 4-0-0
  kHomography3pt1l,  // 3-1-0
  kHomography2pt2l,  // 2-2-0
  kHomography1pt3l,  // 1-3-0
  kHomography4l,     // 0-4-0
  k2pt3line,         // 2-3-0
  k1vp3pt,           // 3-0-1
  k1vp3line,         // 0-3-1
  k2vp2pt,           // 2-0-2
  k1vpOrthline2pt,   // 2-1-1-perp
  k1vp2line1pt,      // 1-2-1-perp
  k1vp2ptOrth,       // 2-0-1-perp
};
constexpr int kNumSolvers = 13;

// What a configuration consumes and how its data must relate.
struct SolverInfo {
  SolverId id;
  const char* code;      // paper notation X-Y-Z (points-lines-VPs)
  const char* function;  // our function name
  int num_points;
  int num_lines;
  int num_vps;
  bool coplanar;         // all points and lines on one plane (homography family)
  bool lines_coplanar;   // the lines lie on one plane (2-3-0, 0-3-1)
  bool orthogonal;       // the first line (or the points' line) is orthogonal to VP 0
  const char* inputs;    // human-readable
  // False for 2-2-0 only: two points and two lines of a plane fix the homography up to a
  // one-parameter family of homologies (centre: the lines' junction, axis: the points' line),
  // so no instance has finitely many poses and the solver always returns none.
  bool well_posed = true;
};

const std::array<SolverInfo, kNumSolvers>& solver_table();
const SolverInfo& solver_info(SolverId id);
// The paper code with "p" in place of the orthogonality sign ("2-1-1p"), for ASCII-only output.
std::string ascii_code(const SolverInfo& info);

// Look-up by paper code ("2-1-1p" or "2-1-1⊥" for the orthogonal ones) or function name.
bool find_solver(const std::string& name, SolverId* id);

// A minimal sample for any configuration, in normalised coordinates. Only the first
// num_points / num_lines / num_vps entries that the configuration uses are read.
struct MinimalSample {
  std::array<Eigen::Vector2d, 5> x1, x2;
  std::array<LineSegment, 4> s1, s2;
  std::array<Eigen::Vector3d, 2> v1, v2;
  bool vp_signs_known = false;
};

// Runs the configuration's solver on the sample; returns the number of poses.
int solve_minimal(SolverId id, const MinimalSample& sample, RelativePoses* poses);

}  // namespace hybrid_vo
