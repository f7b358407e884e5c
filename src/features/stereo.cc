#include "hybrid_vo/features/stereo.h"

#include <algorithm>
#include <cmath>

#include <opencv2/video/tracking.hpp>

#include "hybrid_vo/features/lucas_kanade.h"

namespace hybrid_vo {

StereoMatcher::StereoMatcher(std::vector<cv::Mat> left_pyramid, std::vector<cv::Mat> right_pyramid,
                             std::vector<Eigen::Vector2d> pixels, const PinholeCamera& camera,
                             double baseline_m, const StereoOptions& options,
                             std::vector<double> predicted_disparities)
    : left_(std::move(left_pyramid)),
      right_(std::move(right_pyramid)),
      pixels_(std::move(pixels)),
      camera_(camera),
      baseline_m_(baseline_m),
      options_(options),
      predicted_(std::move(predicted_disparities)) {
  const size_t n = pixels_.size();
  if (predicted_.size() != n) predicted_.clear();
  usable_ = n > 0 && !left_.empty() && !right_.empty() && left_[0].size() == right_[0].size() &&
            camera_.valid() && baseline_m_ > 0.0;
  start_ = options_.search_start_px >= 0.0 ? options_.search_start_px : camera_.fx / 20.0;
  from_.resize(n);
  for (size_t i = 0; i < n; ++i)
    from_[i] = cv::Point2f(static_cast<float>(pixels_[i].x()), static_cast<float>(pixels_[i].y()));
  to_.resize(n);
  back_.resize(n);
  offset_.resize(n);
  found_.assign(n, 0);
  back_found_.assign(n, 0);
  long_way_.assign(n, 1);
}

int StereoMatcher::chunks() const {
  return usable_ ? (static_cast<int>(pixels_.size()) + kChunk - 1) / kChunk : 0;
}

void StereoMatcher::search(int chunk) {
  const int begin = chunk * kChunk;
  const int end = std::min(static_cast<int>(pixels_.size()), begin + kChunk);
  if (!usable_ || begin >= end) return;
  const int cols = right_[0].cols;
  const float max_x = static_cast<float>(cols - 1);
  const cv::Size window(options_.window_px, options_.window_px);
  // Right matches sit at smaller x: each search starts `offset` pixels to the left (clamped to
  // the image), the way back as far to the right. The offset is the predicted disparity or, the
  // long way, start_.
  std::vector<int> short_search, long_search;
  auto start_from = [&](int i, double disparity, bool long_search_way) {
    offset_[i] = static_cast<float>(disparity);
    long_way_[i] = long_search_way;
    to_[i] = cv::Point2f(std::clamp(from_[i].x - offset_[i], 0.0f, std::max(0.0f, from_[i].x)),
                         from_[i].y);
    (long_search_way ? long_search : short_search).push_back(i);
  };
  for (int i = begin; i < end; ++i) {
    const double d = predicted_.empty() ? -1.0 : predicted_[i];
    const bool usable =
        options_.predicted_pyramid_levels >= 0 && std::isfinite(d) && d >= 0.0 && d < cols;
    start_from(i, usable ? d : start_, !usable);
  }
  const int short_levels = std::min(options_.predicted_pyramid_levels, options_.pyramid_levels);
  auto search = [&](const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b,
                    const std::vector<cv::Point2f>& points, const std::vector<int>& which,
                    int levels, std::vector<cv::Point2f>* found_at, std::vector<char>* ok) {
    lucas_kanade_search(a, b, points, which, levels, options_.pyramid_levels, window,
                        options_.max_iterations, found_at, ok);
  };
  search(left_, right_, from_, short_search, short_levels, &to_, &found_);
  // What the short search lost (or found off its row: a wrong prediction) goes the long way.
  for (int i : short_search)
    if (!found_[i] || std::abs(to_[i].y - from_[i].y) > options_.max_row_difference_px)
      start_from(i, start_, true);
  std::sort(long_search.begin(), long_search.end());
  search(left_, right_, from_, long_search, options_.pyramid_levels, &to_, &found_);

  // The left-right check mirrors the forward search, from the same offset and over the same
  // levels. A match off its row is refused whatever the way back says, so it is not searched
  // back (a third of the long searches on KITTI).
  std::vector<int> back_short, back_long;
  for (int i = begin; i < end; ++i) {
    if (!found_[i] || std::abs(from_[i].y - to_[i].y) > options_.max_row_difference_px) continue;
    back_[i] = cv::Point2f(std::clamp(to_[i].x + offset_[i], std::min(to_[i].x, max_x), max_x),
                           to_[i].y);
    (long_way_[i] ? back_long : back_short).push_back(i);
  }
  search(right_, left_, to_, back_short, short_levels, &back_, &back_found_);
  search(right_, left_, to_, back_long, options_.pyramid_levels, &back_, &back_found_);
}

std::vector<Eigen::Vector3d> StereoMatcher::points(std::vector<char>* valid) const {
  const size_t n = pixels_.size();
  std::vector<Eigen::Vector3d> X(n, Eigen::Vector3d::Zero());
  valid->assign(n, 0);
  const double max_lr_sq =
      options_.max_left_right_difference_px * options_.max_left_right_difference_px;
  for (size_t i = 0; i < n && usable_; ++i) {
    // Off its row: never searched back (search).
    if (!found_[i] || !back_found_[i]) continue;
    const double dx = back_[i].x - from_[i].x, dy = back_[i].y - from_[i].y;
    if (dx * dx + dy * dy > max_lr_sq) continue;
    // The mean of the two directions' disparities halves the tracking noise.
    const double disparity = 0.5 * ((from_[i].x - to_[i].x) + (back_[i].x - to_[i].x));
    if (!(disparity >= options_.min_disparity_px)) continue;
    const double Z = camera_.fx * baseline_m_ / disparity;
    const Eigen::Vector2d x = camera_.normalize(pixels_[i]);
    X[i] = Z * Eigen::Vector3d(x.x(), x.y(), 1.0);
    (*valid)[i] = all_finite(X[i]);
  }
  return X;
}

std::vector<cv::Mat> stereo_pyramid(const cv::Mat& image, const StereoOptions& options) {
  std::vector<cv::Mat> pyramid;
  if (!image.empty())
    cv::buildOpticalFlowPyramid(image, pyramid, cv::Size(options.window_px, options.window_px),
                                options.pyramid_levels, true);
  return pyramid;
}

std::vector<Eigen::Vector3d> stereo_points(const cv::Mat& left, const cv::Mat& right,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid, const StereoOptions& options,
                                           const std::vector<double>& predicted_disparities) {
  const bool any = !pixels.empty() && !left.empty() && !right.empty();
  return stereo_points(any ? stereo_pyramid(left, options) : std::vector<cv::Mat>(),
                       any ? stereo_pyramid(right, options) : std::vector<cv::Mat>(), pixels,
                       camera, baseline_m, valid, options, predicted_disparities);
}

std::vector<Eigen::Vector3d> stereo_points(const std::vector<cv::Mat>& left_pyramid,
                                           const std::vector<cv::Mat>& right_pyramid,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid, const StereoOptions& options,
                                           const std::vector<double>& predicted_disparities,
                                           const ParallelFor& parallel) {
  StereoMatcher matcher(left_pyramid, right_pyramid, pixels, camera, baseline_m, options,
                        predicted_disparities);
  run_indices(parallel, matcher.chunks(), [&](int chunk) { matcher.search(chunk); });
  return matcher.points(valid);
}

}  // namespace hybrid_vo
