#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/frontend/camera_model.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

struct StereoOptions {
  double max_row_difference_px = 1.5;  // rectified images: matches stay on their row
  double min_disparity_px = 0.5;       // beyond this the depth is too uncertain to scale with
  int window_px = 21;
};

// Depths of left-image points from a rectified stereo pair (left camera frame, metres): each
// point is tracked into the right image by pyramidal Lucas-Kanade and triangulated from its
// disparity, Z = f B / d. `valid[i]` says whether point i got a depth.
std::vector<Eigen::Vector3d> stereo_points(const cv::Mat& left, const cv::Mat& right,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid,
                                           const StereoOptions& options = {});

// Metric length of a unit translation from points with known 3D positions in the reference
// camera: each observation x (normalised, current camera) gives s from x ~ R X + s t; the median
// is robust to the odd wrong depth. False with fewer than `min_points` usable observations.
bool scale_from_points(const RelativePose& unit_motion, const std::vector<Eigen::Vector3d>& X_ref,
                       const std::vector<Eigen::Vector2d>& x_cur, double* scale,
                       int min_points = 5);

}  // namespace hybrid_vo
