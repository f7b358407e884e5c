#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"

namespace hybrid_vo {

// Colour of VP k (BGR); unlabelled segments are grey.
cv::Scalar vp_colour(int k);

// One view: points (green), segments coloured by their VP label (-1: grey), and the VPs whose
// image lies within twice the image size as crosses. Returns a BGR copy of `image`.
cv::Mat draw_view(const cv::Mat& image, const std::vector<Eigen::Vector2d>& points,
                  const std::vector<LineSegment>& segments, const std::vector<int>& labels,
                  const std::vector<Eigen::Vector3d>& vp_directions, const PinholeCamera& camera);

// Both views side by side; inlier point matches joined by thin lines. Masks select what is drawn
// (empty masks draw everything).
cv::Mat draw_two_view(const cv::Mat& image1, const cv::Mat& image2, const TwoViewMatches& matches,
                      const std::vector<char>& point_mask, const std::vector<char>& line_mask,
                      const PinholeCamera& camera1, const PinholeCamera& camera2);

}  // namespace hybrid_vo
