#include "hybrid_vo/solvers/relpose_1vp_3line.h"

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/solvers/junctions.h"
#include "hybrid_vo/solvers/relpose_1vp_3pt.h"

namespace hybrid_vo {

int relpose_1vp_3line(const Eigen::Vector3d& v1, const Eigen::Vector3d& v2,
                      const std::array<LineSegment, 3>& s1, const std::array<LineSegment, 3>& s2,
                      RelativePoses* poses, bool vp_sign_known) {
  poses->clear();
  Eigen::Vector2d j1[3], j2[3];
  constexpr int kPairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < 3; ++k) {
    const int a = kPairs[k][0], b = kPairs[k][1];
    if (!junction_match(s1[a], s1[b], s2[a], s2[b], &j1[k], &j2[k])) return 0;
  }
  MatchView witnesses;
  witnesses.s1 = s1.data();
  witnesses.s2 = s2.data();
  witnesses.num_segments = 3;
  return relpose_1vp_3pt(v1, v2, j1, j2, witnesses, vp_sign_known, poses);
}

}  // namespace hybrid_vo
