#pragma once

// Sub-pixel refinement of point tracks with an affine warp of each feature's window.
//
// Why: pyramidal Lucas-Kanade (the KLT tracker) moves a window without deforming it. A surface
// that comes closer grows in the image between two frames (by 4-10 % per frame for the
// corridor's near walls and floor), unevenly across a foreshortened window, and a translated
// window then settles off the true position along the point's flow, by an amount and sign that
// depend on where the texture's gradients lie in the window. Along the flow is along the
// epipolar line, so the pose's inlier test cannot see it, but the stereo scale does: on the
// rendered corridor the tracked points of near surfaces lag by 0.024 px (median) at 16-24 px of
// disparity and 0.107 px at 24-40 px, and the scale fitted to them was 0.15-0.25 % short (issue
// 17). An affine window follows the growth: the lag goes (0.001 px) and the spread along the
// flow halves (robust sigma 0.34 to 0.17 px, as precise as the disparities).

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace hybrid_vo {

struct AffineTrackingOptions {
  // Side of the square window (odd). 15 px gives the same scale as the KLT tracker's 21 px on
  // the corridor and KITTI 01 at half the cost (about 9 us per point here).
  int window_px = 15;
  int max_iterations = 10;    // Gauss-Newton iterations per point
  double epsilon_px = 0.005;  // converged when no corner of the window would move farther
  // A refinement that moves the point farther than this from where the tracker put it, or
  // deforms the window by more than max_deformation (|A - I|, largest entry), is not trusted:
  // the point keeps the tracker's position.
  double max_shift_px = 2.0;
  double max_deformation = 0.5;
};

// Refines `to_px[i]`, the track of `from_px[i]` (both pixels, of 8-bit grey images `from` and
// `to`), by inverse compositional Lucas-Kanade (Baker and Matthews 2004) with an affine warp of
// the window and a gain and bias of its brightness, starting from the window as the tracker
// moved it. Returns, per point, whether it was refined; the others keep their position (a
// window that leaves either image, has no texture, changes its brightness beyond a gain of 0.2,
// or moves or deforms beyond the limits: their tracks are not known to sub-pixel accuracy).
std::vector<char> refine_tracks_affine(const cv::Mat& from, const cv::Mat& to,
                                       const std::vector<Eigen::Vector2d>& from_px,
                                       std::vector<Eigen::Vector2d>* to_px,
                                       const AffineTrackingOptions& options = {});

}  // namespace hybrid_vo
