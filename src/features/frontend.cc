#include "hybrid_vo/features/frontend.h"

#include <chrono>

namespace hybrid_vo {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

ImageFeatures extract_features(const GrayImage& image, const FrontendOptions& options) {
  ImageFeatures f;
  if (options.use_points) {
    const auto start = std::chrono::steady_clock::now();
    f.points = detect_point_features(image, options.points);
    f.points_ms = ms_since(start);
  }
  if (options.use_lines) {
    const auto start = std::chrono::steady_clock::now();
    f.lines = detect_line_features(image, options.lines);
    f.lines_ms = ms_since(start);
  }
  return f;
}

TwoViewMatches match_features(const ImageFeatures& a, const ImageFeatures& b,
                              const CameraModel& camera1, const CameraModel& camera2,
                              const FrontendOptions& options, double* match_ms) {
  const auto start = std::chrono::steady_clock::now();
  TwoViewMatches matches;
  if (options.use_points) matches.points = match_point_features(a.points, b.points, options.points);
  if (options.use_lines) matches.lines = match_line_features(a.lines, b.lines, options.lines);
  undistort_matches(camera1, camera2, &matches);
  if (match_ms) *match_ms = ms_since(start);
  return matches;
}

}  // namespace hybrid_vo
