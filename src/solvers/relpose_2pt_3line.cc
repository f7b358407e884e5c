#include "hybrid_vo/solvers/relpose_2pt_3line.h"

#include "hybrid_vo/geometry/cheirality.h"
#include "hybrid_vo/solvers/junctions.h"
#include "hybrid_vo/solvers/relpose_5pt.h"

namespace hybrid_vo {

int relpose_2pt_3line(const std::array<Eigen::Vector2d, 2>& x1,
                      const std::array<Eigen::Vector2d, 2>& x2,
                      const std::array<LineSegment, 3>& s1, const std::array<LineSegment, 3>& s2,
                      RelativePoses* poses) {
  poses->clear();
  Eigen::Vector2d p1[5] = {x1[0], x1[1]}, p2[5] = {x2[0], x2[1]};
  constexpr int kPairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int k = 0; k < 3; ++k) {
    const int a = kPairs[k][0], b = kPairs[k][1];
    if (!junction_match(s1[a], s1[b], s2[a], s2[b], &p1[2 + k], &p2[2 + k])) return 0;
  }
  MatchView witnesses;
  witnesses.x1 = x1.data();
  witnesses.x2 = x2.data();
  witnesses.num_points = 2;
  witnesses.s1 = s1.data();
  witnesses.s2 = s2.data();
  witnesses.num_segments = 3;
  return relpose_5pt(p1, p2, witnesses, poses);
}

}  // namespace hybrid_vo
