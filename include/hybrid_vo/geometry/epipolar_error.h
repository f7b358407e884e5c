#pragma once

#include <Eigen/Core>

#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// Sampson error of a point correspondence in pixels under the pose's F = K2^-T [t]x R K1^-1 (paper
// Sec. 4: the point residual of scoring and refinement), i.e. the first-order distance of (x1, x2)
// to the nearest pair that satisfies the epipolar constraint. NaN when the pose has no
// translation (no epipolar geometry) or a point is not finite.
double sampson_error_px(const PinholeCamera& camera1, const PinholeCamera& camera2,
                        const RelativePose& pose, const Eigen::Vector2d& x1,
                        const Eigen::Vector2d& x2);

}  // namespace hybrid_vo
