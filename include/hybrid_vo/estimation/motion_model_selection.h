#pragma once

// Whether a pair's data hold a translation at all: the full motion (essential matrix, 5
// parameters, a 3-dimensional manifold of point pairs) against a pure rotation (3 parameters, a
// 2-dimensional one), scored on the same point matches by Torr's GRIC (Torr 1998; ORB-SLAM chooses
// between a homography and a fundamental matrix alike). The rotation explains each point to its
// transfer error, the full motion to its Sampson error; GRIC charges the full model for the
// dimension and the parameters it spends, so a translation is kept only where the points move off
// the rotation by more than their noise explains.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

struct MotionModelScores {
  bool rotation_only = false;
  double gric_full = 0.0, gric_rotation = 0.0;  // lower is better
  int points = 0;                               // the matches scored
};

// `inliers` (aligned with `points`, or empty for all) chooses the matches; `sigma_px` is their
// noise per axis (pixels). No finite point or no noise: the full model stays.
MotionModelScores select_motion_model(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                      const std::vector<PointMatch>& points,
                                      const std::vector<char>& inliers, const RelativePose& full,
                                      const Eigen::Matrix3d& rotation, double sigma_px);

}  // namespace hybrid_vo
