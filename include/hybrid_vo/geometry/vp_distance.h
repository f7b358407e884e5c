#pragma once

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// Orthogonal distance of a segment to a vanishing point (Tardif 2009): the distance of an endpoint
// to the line through the segment's midpoint m and the VP v (homogeneous, same coordinates as the
// segment). Since p1 x m = (p1 x p2) / 2 = l / 2 this is (v . l / 2) / |v_xy - v_z m|: signed,
// defined for a VP at infinity (v_z = 0) and independent of the scale and sign of v. It grows with
// the segment's length, so long segments, whose direction is known better, weigh more.
// Returns false when v sits at the midpoint (every line through it passes the VP). `dr_dv`
// receives the gradient when given.
bool tardif_distance(const Eigen::Vector3d& l, const Eigen::Vector2d& m, const Eigen::Vector3d& v,
                     double* r, Eigen::Vector3d* dr_dv = nullptr);

// |distance| for a segment; infinity when v sits at its midpoint or anything is not finite.
double tardif_distance(const LineSegment& s, const Eigen::Vector3d& v);

}  // namespace hybrid_vo
