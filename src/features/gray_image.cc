#include "hybrid_vo/features/gray_image.h"

#include <opencv2/imgproc.hpp>

namespace hybrid_vo {

cv::Mat to_gray8(const cv::Mat& image) {
  cv::Mat gray;
  if (image.channels() == 3)
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4)
    cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  else
    gray = image;
  if (gray.depth() != CV_8U) gray.convertTo(gray, CV_8U);
  return gray;
}

}  // namespace hybrid_vo
