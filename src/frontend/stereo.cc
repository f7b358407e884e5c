#include "hybrid_vo/frontend/stereo.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace hybrid_vo {

std::vector<Eigen::Vector3d> stereo_points(const cv::Mat& left, const cv::Mat& right,
                                           const std::vector<Eigen::Vector2d>& pixels,
                                           const PinholeCamera& camera, double baseline_m,
                                           std::vector<char>* valid, const StereoOptions& options) {
  std::vector<Eigen::Vector3d> X(pixels.size(), Eigen::Vector3d::Zero());
  valid->assign(pixels.size(), 0);
  if (pixels.empty() || left.empty() || right.empty() || left.size() != right.size() ||
      !camera.valid() || !(baseline_m > 0.0))
    return X;
  const double start = options.search_start_px >= 0.0 ? options.search_start_px : camera.fx / 20.0;
  const float max_x = static_cast<float>(left.cols - 1);
  // Right matches sit at smaller x: the search starts `start` pixels to the left (clamped to the
  // image), the way back as far to the right.
  std::vector<cv::Point2f> from, to;
  for (const Eigen::Vector2d& p : pixels) {
    from.emplace_back(p.x(), p.y());
    to.emplace_back(std::clamp(static_cast<float>(p.x() - start), 0.0f, std::max(0.0f, from.back().x)),
                    from.back().y);
  }
  const cv::Size window(options.window_px, options.window_px);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  std::vector<cv::Mat> left_pyramid, right_pyramid;
  cv::buildOpticalFlowPyramid(left, left_pyramid, window, options.pyramid_levels);
  cv::buildOpticalFlowPyramid(right, right_pyramid, window, options.pyramid_levels);
  std::vector<uchar> status, back_status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(left_pyramid, right_pyramid, from, to, status, error, window,
                           options.pyramid_levels, criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point2f> back(to.size());
  for (size_t i = 0; i < to.size(); ++i)
    back[i] = cv::Point2f(std::clamp(static_cast<float>(to[i].x + start), std::min(to[i].x, max_x),
                                     max_x),
                          to[i].y);
  cv::calcOpticalFlowPyrLK(right_pyramid, left_pyramid, to, back, back_status, error, window,
                           options.pyramid_levels, criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
  for (size_t i = 0; i < pixels.size(); ++i) {
    if (!status[i] || !back_status[i]) continue;
    if (std::abs(from[i].y - to[i].y) > options.max_row_difference_px) continue;
    const double dx = back[i].x - from[i].x, dy = back[i].y - from[i].y;
    if (dx * dx + dy * dy > options.max_left_right_difference_px *
                                options.max_left_right_difference_px)
      continue;
    // The mean of the two directions' disparities halves the tracking noise.
    const double disparity = 0.5 * ((from[i].x - to[i].x) + (back[i].x - to[i].x));
    if (!(disparity >= options.min_disparity_px)) continue;
    const double Z = camera.fx * baseline_m / disparity;
    const Eigen::Vector2d n = camera.normalize(pixels[i]);
    X[i] = Z * Eigen::Vector3d(n.x(), n.y(), 1.0);
    (*valid)[i] = all_finite(X[i]);
  }
  return X;
}

}  // namespace hybrid_vo
