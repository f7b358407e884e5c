#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/features/camera_model.h"
#include "hybrid_vo/features/worker_thread.h"
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
  // 11 px: on shared KITTI 01 and the rendered corridor the scale and drift match those of 21 px
  // (within 0.05 %) at 0.36x the instructions (Lucas-Kanade's cost grows with the window's area).
  int window_px = 11;
  int pyramid_levels = 3;
  int max_iterations = 30;  // Lucas-Kanade iterations per pyramid level
  // A point with a predicted disparity (its track's in the previous frame) is searched for from
  // there, over this many levels above full resolution, and only what that short search loses
  // the long way from search_start_px: most points cost half the pyramid. Negative: always long.
  int predicted_pyramid_levels = 1;
};

// Depths of left-image points from a rectified stereo pair (left camera frame, metres): each
// point is tracked into the right image by pyramidal Lucas-Kanade (sub-pixel), tracked back for
// the left-right check, and triangulated from its disparity d (the mean of the two directions),
// Z = f B / d, so that d = f B / Z. `valid[i]` says whether point i got a depth.
// `predicted_disparities` (pixels, NaN where unknown; empty, or one per pixel) says where each
// search starts.
std::vector<Eigen::Vector3d> stereo_points(const cv::Mat& left, const cv::Mat& right,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid,
                                           const StereoOptions& options = {},
                                           const std::vector<double>& predicted_disparities = {});

// An image's pyramid as stereo_points searches it: cv::buildOpticalFlowPyramid with derivatives,
// options.window_px and options.pyramid_levels.
std::vector<cv::Mat> stereo_pyramid(const cv::Mat& image, const StereoOptions& options = {});

// The same with both images' pyramids already built (as stereo_pyramid builds them, or with a
// larger window or more levels), such as the KLT tracker's of the left image: the video front
// end builds each pyramid once. Each point is searched for on its own, so `parallel` may spread
// the points over threads: the result is the same.
std::vector<Eigen::Vector3d> stereo_points(const std::vector<cv::Mat>& left_pyramid,
                                           const std::vector<cv::Mat>& right_pyramid,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid,
                                           const StereoOptions& options = {},
                                           const std::vector<double>& predicted_disparities = {},
                                           const ParallelFor& parallel = {});

// stereo_points in steps, so that a caller can run the searches beside other work: the points
// are searched for in chunks, each chunk on its own (search touches nothing else), on any
// threads and in any order; points() then triangulates them. The result is stereo_points'.
class StereoMatcher {
 public:
  StereoMatcher(std::vector<cv::Mat> left_pyramid, std::vector<cv::Mat> right_pyramid,
                std::vector<Eigen::Vector2d> pixels, const PinholeCamera& camera,
                double baseline_m, const StereoOptions& options = {},
                std::vector<double> predicted_disparities = {});
  int chunks() const;
  void search(int chunk);
  std::vector<Eigen::Vector3d> points(std::vector<char>* valid) const;

 private:
  static constexpr int kChunk = 32;  // points per chunk: fine enough for two threads to share

  std::vector<cv::Mat> left_, right_;
  std::vector<Eigen::Vector2d> pixels_;
  PinholeCamera camera_;
  double baseline_m_ = 0.0;
  StereoOptions options_;
  std::vector<double> predicted_;  // empty or one per point
  bool usable_ = false;            // inputs that can give points at all
  double start_ = 0.0;             // the long way's offset (pixels)
  // Per point: the left pixel, the right match, the way back, the search's offset and outcome.
  std::vector<cv::Point2f> from_, to_, back_;
  std::vector<float> offset_;
  std::vector<char> found_, back_found_, long_way_;
};

}  // namespace hybrid_vo
