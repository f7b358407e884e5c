#pragma once

// Synthetic images for the front end's tests.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace hybrid_vo {
namespace testing {

// Uniform noise blurred by a Gaussian of `sigma` px and stretched to 0..255: corners everywhere,
// and smooth enough for sub-pixel tracking. Draws from OpenCV's global RNG.
inline cv::Mat blurred_noise(int rows, int cols, double sigma) {
  cv::Mat noise(rows, cols, CV_8U);
  cv::randu(noise, 0, 255);
  cv::Mat texture;
  cv::GaussianBlur(noise, texture, cv::Size(0, 0), sigma);
  cv::normalize(texture, texture, 0, 255, cv::NORM_MINMAX);
  return texture;
}

}  // namespace testing
}  // namespace hybrid_vo
