#pragma once

// Internal: MSAC scoring of a relative pose (paper Sec. 4: Sampson error in pixels for point-like
// data, angular error for VPs).

#include <vector>

#include "hybrid_problem.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

class ModelScorer {
 public:
  // A VP residual is an angle in two directions: it counts as two rows, each normalised by its
  // threshold like a point's one row. (It was a tuned weight of 3 points; measured on the four pair
  // sets at gaps 1-3 with 10 runs, 2 rows is as good: doc/pairs.md, "The knobs that stay".)
  static constexpr double kVpRows = 2.0;

  ModelScorer(const HybridProblem& problem, double point_threshold_px, double vp_threshold_rad);

  // Truncated quadratic cost, each term normalised by its squared threshold (so a point costs at
  // most 1 and a VP at most kVpRows). Stops and returns a value above `bound` as soon as the
  // partial sum exceeds it. A pose without translation cannot be scored and costs infinity.
  double cost(const RelativePose& pose, double bound) const;

  // Inlier masks of the pool (at `widen` times the threshold) and the VPs; return the counts.
  int pool_inliers(const RelativePose& pose, std::vector<char>* mask, double widen = 1.0) const;
  int vp_inliers(const RelativePose& pose, std::vector<char>* mask) const;

  // Lines verified by the pose: a junction of the line is an inlier, or the line agrees with the
  // rotation through its inlier VP. Unverifiable lines count as unsupported, so the ratio is a
  // lower bound on the line inlier ratio. `mask` (optional) receives the per-line flags.
  int line_support(const RelativePose& pose, std::vector<char>* mask = nullptr) const;

  // Squared Sampson error in pixels of pool entry i under the fundamental matrix F.
  double squared_sampson(const Eigen::Matrix3d& F, int i) const;
  double squared_sampson(const Eigen::Matrix3d& F, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) const;
  // Angle between d2 and +-R d1 (sign only when known).
  double vp_angle(const Eigen::Matrix3d& R, int k) const;
  Eigen::Matrix3d fundamental(const RelativePose& pose) const;

 private:
  const HybridProblem& problem_;
  double point_threshold_sq_, vp_threshold_sq_;
  Eigen::Matrix3d K1_inverse_, K2_inverse_transpose_;
};

}  // namespace hybrid_vo
