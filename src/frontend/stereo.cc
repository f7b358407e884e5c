#include "hybrid_vo/frontend/stereo.h"

#include <algorithm>
#include <cmath>

#include <opencv2/video/tracking.hpp>

#include "hybrid_vo/frontend/lucas_kanade.h"

namespace hybrid_vo {

std::vector<Eigen::Vector3d> stereo_points(const cv::Mat& left, const cv::Mat& right,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid, const StereoOptions& options,
                                           const std::vector<double>& predicted_disparities) {
  std::vector<cv::Mat> left_pyramid;
  if (!left.empty() && !pixels.empty())
    cv::buildOpticalFlowPyramid(left, left_pyramid, cv::Size(options.window_px, options.window_px),
                                options.pyramid_levels, true);
  return stereo_points(left_pyramid, right, pixels, camera, baseline_m, valid, options,
                       predicted_disparities);
}

std::vector<Eigen::Vector3d> stereo_points(const std::vector<cv::Mat>& left_pyramid,
                                           const cv::Mat& right,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid, const StereoOptions& options,
                                           const std::vector<double>& predicted_disparities) {
  const size_t n = pixels.size();
  std::vector<Eigen::Vector3d> X(n, Eigen::Vector3d::Zero());
  valid->assign(n, 0);
  if (pixels.empty() || left_pyramid.empty() || right.empty() ||
      left_pyramid[0].size() != right.size() || !camera.valid() || !(baseline_m > 0.0))
    return X;
  const bool predicted = predicted_disparities.size() == n;
  const double start = options.search_start_px >= 0.0 ? options.search_start_px : camera.fx / 20.0;
  const float max_x = static_cast<float>(right.cols - 1);
  const cv::Size window(options.window_px, options.window_px);
  std::vector<cv::Mat> right_pyramid;
  cv::buildOpticalFlowPyramid(right, right_pyramid, window, options.pyramid_levels, true);

  // Right matches sit at smaller x: each search starts `offset` pixels to the left (clamped to
  // the image), the way back as far to the right. The offset is the predicted disparity or, the
  // long way, `start`.
  std::vector<cv::Point2f> from(n), to(n), back(n);
  std::vector<float> offset(n);
  std::vector<char> found(n, 0), back_found(n, 0), long_way(n, 1);
  std::vector<int> short_search, long_search;
  auto start_from = [&](size_t i, double disparity, bool long_search_way) {
    offset[i] = static_cast<float>(disparity);
    long_way[i] = long_search_way;
    to[i] = cv::Point2f(std::clamp(from[i].x - offset[i], 0.0f, std::max(0.0f, from[i].x)),
                        from[i].y);
    (long_search_way ? long_search : short_search).push_back(static_cast<int>(i));
  };
  for (size_t i = 0; i < n; ++i) {
    from[i] = cv::Point2f(static_cast<float>(pixels[i].x()), static_cast<float>(pixels[i].y()));
    const double d = predicted ? predicted_disparities[i] : -1.0;
    const bool usable =
        options.predicted_pyramid_levels >= 0 && std::isfinite(d) && d >= 0.0 && d < right.cols;
    start_from(i, usable ? d : start, !usable);
  }
  const int short_levels = std::min(options.predicted_pyramid_levels, options.pyramid_levels);
  auto search = [&](const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b,
                    const std::vector<cv::Point2f>& points, const std::vector<int>& which,
                    int levels, std::vector<cv::Point2f>* found_at, std::vector<char>* ok) {
    lucas_kanade_search(a, b, points, which, levels, options.pyramid_levels, window,
                        options.max_iterations, found_at, ok);
  };
  search(left_pyramid, right_pyramid, from, short_search, short_levels, &to, &found);
  // What the short search lost (or found off its row: a wrong prediction) goes the long way.
  for (int i : short_search)
    if (!found[i] || std::abs(to[i].y - from[i].y) > options.max_row_difference_px)
      start_from(i, start, true);
  std::sort(long_search.begin(), long_search.end());
  search(left_pyramid, right_pyramid, from, long_search, options.pyramid_levels, &to, &found);

  // The left-right check mirrors the forward search, from the same offset and over the same levels.
  std::vector<int> back_short, back_long;
  for (size_t i = 0; i < n; ++i) {
    if (!found[i]) continue;
    back[i] = cv::Point2f(std::clamp(to[i].x + offset[i], std::min(to[i].x, max_x), max_x),
                          to[i].y);
    (long_way[i] ? back_long : back_short).push_back(static_cast<int>(i));
  }
  search(right_pyramid, left_pyramid, to, back_short, short_levels, &back, &back_found);
  search(right_pyramid, left_pyramid, to, back_long, options.pyramid_levels, &back, &back_found);

  const double max_lr_sq = options.max_left_right_difference_px * options.max_left_right_difference_px;
  for (size_t i = 0; i < n; ++i) {
    if (!found[i] || !back_found[i]) continue;
    if (std::abs(from[i].y - to[i].y) > options.max_row_difference_px) continue;
    const double dx = back[i].x - from[i].x, dy = back[i].y - from[i].y;
    if (dx * dx + dy * dy > max_lr_sq) continue;
    // The mean of the two directions' disparities halves the tracking noise.
    const double disparity = 0.5 * ((from[i].x - to[i].x) + (back[i].x - to[i].x));
    if (!(disparity >= options.min_disparity_px)) continue;
    const double Z = camera.fx * baseline_m / disparity;
    const Eigen::Vector2d x = camera.normalize(pixels[i]);
    X[i] = Z * Eigen::Vector3d(x.x(), x.y(), 1.0);
    (*valid)[i] = all_finite(X[i]);
  }
  return X;
}

}  // namespace hybrid_vo
