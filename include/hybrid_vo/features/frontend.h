#pragma once

#include <opencv2/core.hpp>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/features/camera_model.h"
#include "hybrid_vo/features/line_matching.h"
#include "hybrid_vo/features/point_matching.h"

namespace hybrid_vo {

struct FrontendOptions {
  bool use_points = true;
  bool use_lines = true;
  PointMatchingOptions points;
  LineMatchingOptions lines;
};

// Everything detected in one image, so that an image is described once and matched many times.
struct ImageFeatures {
  PointFeatures points;
  LineFeatures lines;
  double points_ms = 0.0, lines_ms = 0.0;  // detection and description
};

// Converted to grey once for both detectors.
ImageFeatures extract_features(const GrayImage& image, const FrontendOptions& options = {});

// Point and segment matches between two images, undistorted, in the estimator's input types.
// `match_ms` receives the matching time when given.
TwoViewMatches match_features(const ImageFeatures& a, const ImageFeatures& b,
                              const CameraModel& camera1, const CameraModel& camera2,
                              const FrontendOptions& options = {}, double* match_ms = nullptr);

}  // namespace hybrid_vo
