#include "hybrid_vo/solvers/relpose_1vp_2line_1pt.h"

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/solvers/junctions.h"
#include "hybrid_vo/solvers/relpose_1vp_orthline_2pt.h"

namespace hybrid_vo {

int relpose_1vp_2line_1pt(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                          const std::array<LineSegment, 2>& s1,
                          const std::array<LineSegment, 2>& s2, const Eigen::Vector2d& x1,
                          const Eigen::Vector2d& x2, RelativePoses* poses, bool vp_sign_known) {
  poses->clear();
  Eigen::Vector2d p1[2] = {x1}, p2[2] = {x2};
  if (!junction_match(s1[0], s1[1], s2[0], s2[1], &p1[1], &p2[1])) return 0;
  MatchView witnesses;
  witnesses.x1 = &x1;
  witnesses.x2 = &x2;
  witnesses.num_points = 1;
  witnesses.s1 = s1.data();
  witnesses.s2 = s2.data();
  witnesses.num_segments = 2;
  return relpose_1vp_orthline_2pt(v1, v2, s1[0].line(), s2[0].line(), p1, p2, witnesses,
                                  vp_sign_known, poses);
}

}  // namespace hybrid_vo
