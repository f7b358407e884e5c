#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

enum class LineDetector {
  kLsd,  // cv::createLineSegmentDetector (von Gioi et al.), the paper's detector family
  kFld,  // cv::ximgproc::createFastLineDetector (Lee et al.), faster, fewer short segments
};

struct LineDetectionOptions {
  LineDetector detector = LineDetector::kLsd;
  double min_length_px = 20.0;  // shorter segments carry little direction and match poorly
  int max_segments = 0;         // keep only the longest ones; 0 keeps all
};

// Line segments of a grayscale (or BGR, converted) image, in pixels. Empty for an empty image.
std::vector<LineSegment> detect_line_segments(const cv::Mat& image,
                                              const LineDetectionOptions& options = {});

}  // namespace hybrid_vo
