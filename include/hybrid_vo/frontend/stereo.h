#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/frontend/camera_model.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

struct StereoOptions {
  double max_row_difference_px = 1.0;  // rectified images: matches stay on their row
  double min_disparity_px = 0.5;       // a point at infinity has none; below, the sign is noise
  // Left-right check: the right match, tracked back into the left image from its own position,
  // must land within this of the left pixel (occlusions, repeated texture and drifted tracks
  // do not come back).
  double max_left_right_difference_px = 0.5;
  // Both searches start this many pixels towards the other camera's match (right matches sit at
  // smaller x): the disparity of a point at 20 baselines, f / 20 (36 px on KITTI, 23 px on the
  // rendered corridor). Near points then lie within the pyramid's reach, far points a few
  // coarse pixels away. Negative: f / 20 of the camera.
  double search_start_px = -1.0;
  int window_px = 21;
  int pyramid_levels = 3;
};

// Depths of left-image points from a rectified stereo pair (left camera frame, metres): each
// point is tracked into the right image by pyramidal Lucas-Kanade (sub-pixel), tracked back for
// the left-right check, and triangulated from its disparity d (the mean of the two directions),
// Z = f B / d, so that d = f B / Z. `valid[i]` says whether point i got a depth.
std::vector<Eigen::Vector3d> stereo_points(const cv::Mat& left, const cv::Mat& right,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid,
                                           const StereoOptions& options = {});

}  // namespace hybrid_vo
