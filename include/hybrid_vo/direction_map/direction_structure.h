#pragma once

// The structure the map's directions form, tested, never assumed: which pairs are orthogonal
// within their uncertainty, the orthogonal triads (Manhattan), and the verticals of an Atlanta
// world (one direction orthogonal to several horizontals that are not orthogonal to each other:
// the white panels, whose "horizontal" edges are a few degrees apart). Nothing here moves a
// direction: a panel that is not square keeps its angle.

#include <array>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/option_fields.h"

namespace hybrid_vo {

struct DirectionStructureOptions {
  // Orthogonal when the angle's deviation from 90 degrees passes this chi-square (1 dof, 99 %)
  // under both directions' covariances plus the world's own tolerance (degrees): builders'
  // right angles are not exact.
  double orthogonal_chi2 = 6.63;
  double orthogonal_tolerance_deg = 0.5;
};

template <typename Visit>
void visit_fields(DirectionStructureOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(positive(), o.orthogonal_chi2);
  HYBRID_VO_FIELDS(non_negative(), o.orthogonal_tolerance_deg);
}

// A direction as the structure sees it: its id, unit direction and tangent covariance.
struct StructureDirection {
  int id = -1;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

struct DirectionStructure {
  std::vector<std::array<int, 2>> orthogonal;  // ids, each pair once
  std::vector<std::array<int, 3>> triads;      // mutually orthogonal ids (Manhattan)
  std::vector<int> verticals;                  // Atlanta verticals (ids)
  int free = 0;  // directions orthogonal to none
  bool is_orthogonal(int a, int b) const;
};

// The deviation of the angle between two directions from 90 degrees, squared, over its variance
// (sign-agnostic). Infinity when the variance is zero and the deviation is not.
double orthogonality_chi2(const StructureDirection& a, const StructureDirection& b,
                          double tolerance_deg);

DirectionStructure find_structure(const std::vector<StructureDirection>& directions,
                                  const DirectionStructureOptions& options = {});

}  // namespace hybrid_vo
