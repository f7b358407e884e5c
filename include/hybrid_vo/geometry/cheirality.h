#pragma once

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// Non-owning view of point and segment matches in normalised image coordinates, used to decide
// which candidate poses put the observed geometry in front of both cameras.
struct MatchView {
  const Eigen::Vector2d* x1 = nullptr;
  const Eigen::Vector2d* x2 = nullptr;
  int num_points = 0;
  const LineSegment* s1 = nullptr;
  const LineSegment* s2 = nullptr;
  int num_segments = 0;
};

// Given R and t up to sign, flips t so that every point match triangulates in front of both
// cameras and every segment endpoint back-projects onto the matched 3D line at positive depth.
// Returns false when no sign of t satisfies all of them. Matches without parallax (or segments
// whose plane contains the baseline) say nothing and are skipped.
bool orient_translation(const Eigen::Matrix3d& R, Eigen::Vector3d* t, const MatchView& matches);

// orient_translation for point matches given as rays in camera 2's frame: r[i] = R x1_i and
// q[i] = x2_i, each up to a positive scale, in any rotated copy of that frame (t in the same copy).
// Solvers that work in a canonical frame decide the sign there, before forming R.
bool orient_translation_rays(const Eigen::Vector3d* r, const Eigen::Vector3d* q, int n,
                             Eigen::Vector3d* t);

// Same test with a majority vote instead of unanimity, for a model fitted to many noisy matches:
// flips t when more matches lie in front with -t than with t. Returns the margin of votes for the
// chosen sign (0: undecided, t kept).
int orient_translation_by_majority(const Eigen::Matrix3d& R, Eigen::Vector3d* t,
                                   const MatchView& matches);

}  // namespace hybrid_vo
