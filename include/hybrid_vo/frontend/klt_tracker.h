#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/estimation/matches.h"

namespace hybrid_vo {

struct KltTrackerOptions {
  int max_features = 1000;  // a cap on the features tracked (and so on the matches per pair)
  int grid_cols = 8, grid_rows = 6;  // bucketing: re-detection fills empty cells first
  double min_distance_px = 10.0;     // between tracked features
  double quality_level = 0.01;       // of cv::goodFeaturesToTrack
  int window_px = 21;
  int pyramid_levels = 3;
  double max_forward_backward_px = 1.0;  // forward-backward check of each track
};

// Sparse optical-flow tracking of corners between consecutive video frames, with re-detection in
// empty buckets; each feature keeps a stable id across frames.
class KltTracker {
 public:
  explicit KltTracker(const KltTrackerOptions& options = {});
  // Tracks the current features into `image` (grayscale) and re-detects. Returns the matches
  // between the previous frame and this one (pixels) and their track ids. The first call (or the
  // first after reset) returns no matches.
  std::vector<PointMatch> track(const cv::Mat& image, std::vector<int64_t>* ids = nullptr);
  void reset();
  int num_tracks() const;
  // Every feature of the last frame (tracked and newly detected) and its id.
  const std::vector<cv::Point2f>& points() const { return points_; }
  const std::vector<int64_t>& ids() const { return ids_; }

 private:
  KltTrackerOptions options_;
  cv::Mat previous_;
  std::vector<cv::Point2f> points_;
  std::vector<int64_t> ids_;
  int64_t next_id_ = 0;
};

}  // namespace hybrid_vo
