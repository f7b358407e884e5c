#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace hybrid_vo {

// Pyramidal Lucas-Kanade (OpenCV) for the points `which` of `from` (in `from_pyramid`) into
// `to_pyramid`, both built by cv::buildOpticalFlowPyramid with a window at least as large as `window`.
// A short search starts at `(*to)[i]` and spans `levels` levels above full resolution; a long one
// (levels < 0) starts at the point itself and spans all `pyramid_levels`. Writes `to` and `found`
// of those points only: the KLT tracker and the stereo matcher both search a few points the
// short way from a prediction and the rest the long way.
void lucas_kanade_search(const std::vector<cv::Mat>& from_pyramid,
                         const std::vector<cv::Mat>& to_pyramid,
                         const std::vector<cv::Point2f>& from, const std::vector<int>& which,
                         int levels, int pyramid_levels, cv::Size window, int max_iterations,
                         std::vector<cv::Point2f>* to, std::vector<char>* found);

}  // namespace hybrid_vo
