#pragma once

#include <opencv2/core.hpp>

namespace hybrid_vo {

// The 8-bit single-channel image every detector and tracker works on: BGR(A) converted to grey,
// other depths converted to 8 bit; a grey 8-bit input is returned as is (no copy).
cv::Mat to_gray8(const cv::Mat& image);

}  // namespace hybrid_vo
