#include "hybrid_vo/frontend/klt_tracker.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "hybrid_vo/frontend/gray_image.h"

namespace hybrid_vo {

KltTracker::KltTracker(const KltTrackerOptions& options) : options_(options) {}

void KltTracker::reset() {
  previous_.release();
  points_.clear();
  ids_.clear();
}

int KltTracker::num_tracks() const { return static_cast<int>(points_.size()); }

std::vector<PointMatch> KltTracker::track(const cv::Mat& image, std::vector<int64_t>* ids) {
  std::vector<PointMatch> matches;
  if (ids) ids->clear();
  if (image.empty()) return matches;
  const cv::Mat gray = to_gray8(image);
  if (!previous_.empty() && previous_.size() != gray.size()) reset();

  if (!previous_.empty() && !points_.empty()) {
    std::vector<cv::Point2f> next, back;
    std::vector<uchar> status, back_status;
    std::vector<float> error;
    const cv::Size window(options_.window_px, options_.window_px);
    cv::calcOpticalFlowPyrLK(previous_, gray, points_, next, status, error, window,
                             options_.pyramid_levels);
    // Forward-backward consistency (Kalal et al. 2010) rejects drifting and occluded tracks.
    cv::calcOpticalFlowPyrLK(gray, previous_, next, back, back_status, error, window,
                             options_.pyramid_levels);
    std::vector<cv::Point2f> kept;
    std::vector<int64_t> kept_ids;
    const cv::Rect2f bounds(0.0f, 0.0f, gray.cols - 1.0f, gray.rows - 1.0f);
    const double max_fb_sq = options_.max_forward_backward_px * options_.max_forward_backward_px;
    for (size_t i = 0; i < points_.size(); ++i) {
      if (!status[i] || !back_status[i] || !bounds.contains(next[i])) continue;
      const cv::Point2f d = back[i] - points_[i];
      if (d.dot(d) > max_fb_sq) continue;
      PointMatch m;
      m.x1 = Eigen::Vector2d(points_[i].x, points_[i].y);
      m.x2 = Eigen::Vector2d(next[i].x, next[i].y);
      matches.push_back(m);
      if (ids) ids->push_back(ids_[i]);
      kept.push_back(next[i]);
      kept_ids.push_back(ids_[i]);
    }
    points_ = std::move(kept);
    ids_ = std::move(kept_ids);
  }

  // Re-detection by buckets keeps features spread over the image (a cluster of tracks on one
  // textured object makes a poorly conditioned relative pose). With fewer features than cells
  // the grid gets coarser, so that every cell has a quota of at least one and max_features stays
  // a cap: the features, and so the matches that reach the estimator, never exceed it.
  const int max_features = std::max(1, options_.max_features);
  int cols = std::max(1, options_.grid_cols), rows = std::max(1, options_.grid_rows);
  while (cols * rows > max_features && (cols > 1 || rows > 1)) {
    if (cols >= rows) --cols;
    else --rows;
  }
  const int cells = cols * rows;
  const int quota = std::max(1, max_features / cells);
  const int cell_w = (gray.cols + cols - 1) / cols;
  const int cell_h = (gray.rows + rows - 1) / rows;
  std::vector<int> count(cells, 0);
  cv::Mat mask(gray.size(), CV_8U, cv::Scalar(255));
  for (const cv::Point2f& p : points_) {
    const int cx = std::min(cols - 1, static_cast<int>(p.x) / cell_w);
    const int cy = std::min(rows - 1, static_cast<int>(p.y) / cell_h);
    ++count[cy * cols + cx];
    cv::circle(mask, p, static_cast<int>(options_.min_distance_px), cv::Scalar(0), cv::FILLED);
  }
  for (int cy = 0; cy < rows; ++cy) {
    for (int cx = 0; cx < cols; ++cx) {
      const int room = max_features - static_cast<int>(points_.size());
      const int missing = std::min(room, quota - count[cy * cols + cx]);
      if (missing <= 0) continue;
      const cv::Rect cell = cv::Rect(cx * cell_w, cy * cell_h, cell_w, cell_h) &
                            cv::Rect(0, 0, gray.cols, gray.rows);
      if (cell.width < 8 || cell.height < 8) continue;
      std::vector<cv::Point2f> corners;
      cv::goodFeaturesToTrack(gray(cell), corners, missing, options_.quality_level,
                              options_.min_distance_px, mask(cell));
      for (const cv::Point2f& c : corners) {
        points_.push_back(c + cv::Point2f(static_cast<float>(cell.x), static_cast<float>(cell.y)));
        ids_.push_back(next_id_++);
      }
    }
  }
  // Tracks crowding into a few cells can still exceed the cap: keep the oldest (lowest ids).
  if (static_cast<int>(points_.size()) > max_features) {
    std::vector<size_t> order(points_.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return ids_[a] < ids_[b]; });
    order.resize(max_features);
    std::sort(order.begin(), order.end());
    std::vector<cv::Point2f> kept;
    std::vector<int64_t> kept_ids;
    for (size_t i : order) {
      kept.push_back(points_[i]);
      kept_ids.push_back(ids_[i]);
    }
    points_ = std::move(kept);
    ids_ = std::move(kept_ids);
  }
  previous_ = gray.clone();
  return matches;
}

}  // namespace hybrid_vo
