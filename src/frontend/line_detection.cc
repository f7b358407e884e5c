#include "hybrid_vo/frontend/line_detection.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

#include "hybrid_vo/frontend/gray_image.h"

namespace hybrid_vo {

std::vector<LineSegment> detect_line_segments(const cv::Mat& image,
                                              const LineDetectionOptions& options) {
  std::vector<LineSegment> segments;
  if (image.empty()) return segments;
  const cv::Mat gray = to_gray8(image);

  std::vector<cv::Vec4f> raw;
  if (options.detector == LineDetector::kLsd) {
    cv::createLineSegmentDetector(cv::LSD_REFINE_STD)->detect(gray, raw);
  } else {
    const int min_length = static_cast<int>(std::max(1.0, options.min_length_px));
    cv::ximgproc::createFastLineDetector(min_length)->detect(gray, raw);
  }
  for (const cv::Vec4f& r : raw) {
    LineSegment s({r[0], r[1]}, {r[2], r[3]});
    if (all_finite(s.p1) && all_finite(s.p2) && s.length() >= options.min_length_px)
      segments.push_back(s);
  }
  if (options.max_segments > 0 && static_cast<int>(segments.size()) > options.max_segments) {
    std::partial_sort(segments.begin(), segments.begin() + options.max_segments, segments.end(),
                      [](const LineSegment& a, const LineSegment& b) {
                        return a.length() > b.length();
                      });
    segments.resize(options.max_segments);
  }
  return segments;
}

}  // namespace hybrid_vo
