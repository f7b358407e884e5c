#pragma once

#include <opencv2/core.hpp>

namespace hybrid_vo {

// The 8-bit single-channel image every detector and tracker works on: BGR(A) converted to grey,
// other depths converted to 8 bit; a grey 8-bit input is returned as is (no copy).
cv::Mat to_gray8(const cv::Mat& image);

// An image already in that form. The front end's detectors and trackers take one, so that a
// video frame is converted once, where it comes in, and its stages share the result; a cv::Mat
// passed instead is converted on the way in (implicitly, so callers with colour images, the
// Python bindings and the tools, work as before; a grey 8-bit one costs no copy).
class GrayImage {
 public:
  GrayImage() = default;
  GrayImage(const cv::Mat& image) : gray_(to_gray8(image)) {}  // implicit: see above
  const cv::Mat& mat() const { return gray_; }
  bool empty() const { return gray_.empty(); }

 private:
  cv::Mat gray_;
};

}  // namespace hybrid_vo
