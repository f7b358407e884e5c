#include "hybrid_vo/solvers/junctions.h"

namespace hybrid_vo {

bool junction_match(const LineSegment& a1, const LineSegment& b1, const LineSegment& a2,
                    const LineSegment& b2, Eigen::Vector2d* x1, Eigen::Vector2d* x2) {
  // 1e6 in normalised coordinates is far beyond any image: such a junction is a vanishing point.
  constexpr double kFarthest = 1e6;
  return intersect_lines(a1.line(), b1.line(), x1, kFarthest) &&
         intersect_lines(a2.line(), b2.line(), x2, kFarthest);
}

}  // namespace hybrid_vo
