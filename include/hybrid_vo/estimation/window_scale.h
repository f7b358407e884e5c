#pragma once

// One scale over a window of monocular keyframes (issue 58). Monocular odometry knows each
// keyframe link's translation up to its length; a length handed from one link to the next through
// the points of a single pair wanders. Here the last few links and the points tracked across them
// are fitted together: every link has a free log-scale on its given translation (the links held
// fixed set the gauge), every point an inverse depth along its ray in the first camera of the
// window that saw it, and the rotations and translation directions stay the pairs'. It is a local
// bundle adjustment (SVO's, ORB-SLAM's) reduced to the state that drifts in monocular odometry,
// the scale (Strasdat, Montiel and Davison, "Scale drift-aware large scale monocular SLAM", RSS
// 2010), solved as estimate_stereo_scale is: Gauss-Newton with each inverse depth eliminated by
// its Schur complement (a system as small as the number of links, whatever the number of points),
// Cauchy reweighting of each point, halved steps until the robust cost decreases.

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

// A point of the window: its ray in the anchor camera, where it was first seen, and its sightings
// in later cameras, all in normalised image coordinates (K^-1 x, undistorted).
struct WindowPoint {
  int anchor = 0;
  Eigen::Vector2d x_anchor = Eigen::Vector2d::Zero();
  std::vector<std::pair<int, Eigen::Vector2d>> seen;  // (camera > anchor, x)
  // A start for its inverse depth in the anchor camera (<= 0: triangulated from the sighting
  // farthest along the chain at the given lengths).
  double rho = 0.0;
};

struct WindowScaleOptions {
  // Noise of a normalised coordinate (pixels over the focal length) in every sighting; the anchor
  // ray is taken as exact (its noise moves the inverse depth, which is free, more than the
  // scales). The overall level is estimated from the fit (the variance factor).
  double point_sigma = 1e-3;
  double loss_scale = 3.0;  // Cauchy, on each point's whitened residual norm (sigmas)
  int max_iterations = 20;
  // A free link needs this many points that tie it to another link (seen on both sides of one of
  // its ends: a point seen by two cameras only fixes its own depth, not a ratio of lengths).
  int min_tying_points = 10;
  // A free link whose log-scale comes out less sure than this (a factor of e^0.5) fails the fit.
  double max_log_sigma = 0.5;
};

struct WindowScaleEstimate {
  bool ok = false;
  std::vector<double> scales;      // per link, the factor on its given t (1 for a fixed link)
  Eigen::MatrixXd log_covariance;  // of the links' log-scales (fixed links: zero rows/columns)
  std::vector<double> rho;         // per point, in its anchor camera (0: left out)
  std::vector<double> rho_sigma;   // its standard deviation (infinite: left out)
  std::vector<char> inlier;        // per point: Cauchy weight above 1/2 at the end
  int points_used = 0, inliers = 0, iterations = 0;
  double variance_factor = 1.0;  // weighted residual variance over the modelled one
};

constexpr int kMaxFreeLinks = 16;

// Cameras 0..L along a chain of L links: camera j+1 sees X_{j+1} = R_j X_j + s_j t_j, with
// links[j] = (R_j, t_j). fixed[j] holds s_j at 1; at least one link must be fixed. Not ok (and
// nothing estimated) when an input is not finite, a point's cameras are out of order or out of
// range, no link is fixed or more than kMaxFreeLinks are free, a free link has fewer than
// min_tying_points tying points or ends less sure than max_log_sigma, or the fit diverges. Points that cannot be triangulated (along the
// translation, behind a camera) are left out.
WindowScaleEstimate estimate_window_scales(const std::vector<RelativePose>& links,
                                           const std::vector<char>& fixed,
                                           const std::vector<WindowPoint>& points,
                                           const WindowScaleOptions& options = {});

}  // namespace hybrid_vo
