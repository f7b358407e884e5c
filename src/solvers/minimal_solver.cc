#include "hybrid_vo/solvers/minimal_solver.h"

#include "hybrid_vo/solvers/relpose_1vp_2line_1pt.h"
#include "hybrid_vo/solvers/relpose_1vp_2pt_orth.h"
#include "hybrid_vo/solvers/relpose_1vp_3line.h"
#include "hybrid_vo/solvers/relpose_1vp_3pt.h"
#include "hybrid_vo/solvers/relpose_1vp_orthline_2pt.h"
#include "hybrid_vo/solvers/relpose_2pt_3line.h"
#include "hybrid_vo/solvers/relpose_2vp_2pt.h"
#include "hybrid_vo/solvers/relpose_5pt.h"
#include "hybrid_vo/solvers/relpose_homography.h"

namespace hybrid_vo {

const std::array<SolverInfo, kNumSolvers>& solver_table() {
  static const std::array<SolverInfo, kNumSolvers> table = {{
      {SolverId::k5pt, "5-0-0", "relpose_5pt", 5, 0, 0, false, false, false, "5 points"},
      {SolverId::kHomography4pt, "4-0-0", "relpose_homography_4pt", 4, 0, 0, true, false, false,
       "4 coplanar points"},
      {SolverId::kHomography3pt1l, "3-1-0", "relpose_homography_3pt_1line", 3, 1, 0, true, false,
       false, "3 points + 1 line, coplanar"},
      {SolverId::kHomography2pt2l, "2-2-0", "relpose_homography_2pt_2line", 2, 2, 0, true, false,
       false, "2 points + 2 lines, coplanar", false},
      {SolverId::kHomography1pt3l, "1-3-0", "relpose_homography_1pt_3line", 1, 3, 0, true, false,
       false, "1 point + 3 lines, coplanar"},
      {SolverId::kHomography4l, "0-4-0", "relpose_homography_4line", 0, 4, 0, true, false, false,
       "4 coplanar lines"},
      {SolverId::k2pt3line, "2-3-0", "relpose_2pt_3line", 2, 3, 0, false, true, false,
       "2 points + 3 coplanar lines"},
      {SolverId::k1vp3pt, "3-0-1", "relpose_1vp_3pt", 3, 0, 1, false, false, false,
       "1 VP + 3 points"},
      {SolverId::k1vp3line, "0-3-1", "relpose_1vp_3line", 0, 3, 1, false, true, false,
       "1 VP + 3 coplanar lines"},
      {SolverId::k2vp2pt, "2-0-2", "relpose_2vp_2pt", 2, 0, 2, false, false, false,
       "2 VPs + 2 points"},
      {SolverId::k1vpOrthline2pt, "2-1-1⊥", "relpose_1vp_orthline_2pt", 2, 1, 1, false, false,
       true, "1 VP + 1 line ⊥ VP + 2 points"},
      {SolverId::k1vp2line1pt, "1-2-1⊥", "relpose_1vp_2line_1pt", 1, 2, 1, false, false, true,
       "1 VP + 2 intersecting lines (first ⊥ VP) + 1 point"},
      {SolverId::k1vp2ptOrth, "2-0-1⊥", "relpose_1vp_2pt_orth", 2, 0, 1, false, false, true,
       "1 VP + 2 points whose line is ⊥ VP"},
  }};
  return table;
}

const SolverInfo& solver_info(SolverId id) { return solver_table()[static_cast<int>(id)]; }

std::string ascii_code(const SolverInfo& info) {
  std::string code = info.code;
  const std::string perp = "⊥";
  const auto pos = code.find(perp);
  if (pos != std::string::npos) code.replace(pos, perp.size(), "p");
  return code;
}

bool find_solver(const std::string& name, SolverId* id) {
  for (const SolverInfo& info : solver_table()) {
    if (name == info.code || name == ascii_code(info) || name == info.function) {
      *id = info.id;
      return true;
    }
  }
  return false;
}

int solve_minimal(SolverId id, const MinimalSample& s, RelativePoses* poses) {
  const bool known = s.vp_signs_known;
  switch (id) {
    case SolverId::k5pt:
      return relpose_5pt(s.x1, s.x2, poses);
    case SolverId::kHomography4pt:
    case SolverId::kHomography3pt1l:
    case SolverId::kHomography2pt2l:
    case SolverId::kHomography1pt3l:
    case SolverId::kHomography4l: {
      const SolverInfo& info = solver_info(id);
      return relpose_homography(s.x1.data(), s.x2.data(), info.num_points, s.s1.data(),
                                s.s2.data(), info.num_lines, poses);
    }
    case SolverId::k2pt3line:
      return relpose_2pt_3line({s.x1[0], s.x1[1]}, {s.x2[0], s.x2[1]}, {s.s1[0], s.s1[1], s.s1[2]},
                               {s.s2[0], s.s2[1], s.s2[2]}, poses);
    case SolverId::k1vp3pt:
      return relpose_1vp_3pt(s.v1[0], s.v2[0], {s.x1[0], s.x1[1], s.x1[2]},
                             {s.x2[0], s.x2[1], s.x2[2]}, poses, known);
    case SolverId::k1vp3line:
      return relpose_1vp_3line(s.v1[0], s.v2[0], {s.s1[0], s.s1[1], s.s1[2]},
                               {s.s2[0], s.s2[1], s.s2[2]}, poses, known);
    case SolverId::k2vp2pt:
      return relpose_2vp_2pt(s.v1, s.v2, {s.x1[0], s.x1[1]}, {s.x2[0], s.x2[1]}, poses, known);
    case SolverId::k1vpOrthline2pt:
      return relpose_1vp_orthline_2pt(s.v1[0], s.v2[0], s.s1[0], s.s2[0], {s.x1[0], s.x1[1]},
                                      {s.x2[0], s.x2[1]}, poses, known);
    case SolverId::k1vp2line1pt:
      return relpose_1vp_2line_1pt(s.v1[0], s.v2[0], {s.s1[0], s.s1[1]}, {s.s2[0], s.s2[1]},
                                   s.x1[0], s.x2[0], poses, known);
    case SolverId::k1vp2ptOrth:
      return relpose_1vp_2pt_orth(s.v1[0], s.v2[0], {s.x1[0], s.x1[1]}, {s.x2[0], s.x2[1]}, poses,
                                  known);
  }
  poses->clear();
  return 0;
}

}  // namespace hybrid_vo
