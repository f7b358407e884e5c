#include "hybrid_vo/features/lucas_kanade.h"

#include <algorithm>

#include <opencv2/video/tracking.hpp>

namespace hybrid_vo {

void lucas_kanade_search(const std::vector<cv::Mat>& from_pyramid,
                         const std::vector<cv::Mat>& to_pyramid,
                         const std::vector<cv::Point2f>& from, const std::vector<int>& which,
                         int levels, int pyramid_levels, cv::Size window, int max_iterations,
                         std::vector<cv::Point2f>* to, std::vector<char>* found) {
  if (which.empty()) return;
  std::vector<cv::Point2f> a, b;
  a.reserve(which.size());
  b.reserve(which.size());
  for (int i : which) {
    a.push_back(from[i]);
    b.push_back((*to)[i]);
  }
  // No error output: OpenCV then skips the pass over each window that measures it.
  std::vector<uchar> status;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                                  std::max(1, max_iterations), 0.01);
  if (levels < 0) {
    cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, a, b, status, cv::noArray(), window,
                             pyramid_levels, criteria);
  } else {
    cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, a, b, status, cv::noArray(), window,
                             levels, criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
  }
  for (size_t k = 0; k < which.size(); ++k) {
    (*to)[which[k]] = b[k];
    (*found)[which[k]] = status[k] != 0;
  }
}

}  // namespace hybrid_vo
