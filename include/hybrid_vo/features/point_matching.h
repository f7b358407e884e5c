#pragma once

#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/features/gray_image.h"

namespace hybrid_vo {

enum class PointFeatureType {
  kSift,  // cv::SIFT (Lowe 2004): slower, the most reliable across wide baselines
  kOrb,   // cv::ORB (Rublee et al. 2011): an order of magnitude faster, for video
};

// Defaults: SIFT with 4000 features for wide-baseline pairs. For video at frame rate use
// `video_point_matching_options()` (ORB), which keeps a KITTI pair near the 30 ms budget.
struct PointMatchingOptions {
  PointFeatureType type = PointFeatureType::kSift;
  int max_features = 4000;  // per image; VisualOdometry caps its KLT tracks by it too
  double ratio = 0.8;  // Lowe's ratio test on the two nearest neighbours
  bool mutual = true;  // keep a match only when it is the best in both directions
  // SIFT: layers per octave and contrast threshold (OpenCV's defaults, Lowe's values).
  int sift_octave_layers = 3;
  double sift_contrast_threshold = 0.04;
  // ORB: pyramid and FAST threshold (OpenCV's defaults).
  int orb_levels = 8;
  double orb_scale_factor = 1.2;
  int orb_fast_threshold = 20;
};

// The video preset: ORB with 1000 features on 4 pyramid levels (~4 ms per KITTI frame, against
// ~85 ms for SIFT).
PointMatchingOptions video_point_matching_options();

// Keypoints and descriptors of one image.
struct PointFeatures {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
};

// Detection and description for wide-baseline matching. Empty features for an empty image.
PointFeatures detect_point_features(const GrayImage& image,
                                    const PointMatchingOptions& options = {});

// Ratio-tested (and optionally mutual) nearest-neighbour matches, in pixels. `pairs` receives the
// keypoint indices of each match when given.
std::vector<PointMatch> match_point_features(const PointFeatures& a, const PointFeatures& b,
                                             const PointMatchingOptions& options = {},
                                             std::vector<std::pair<int, int>>* pairs = nullptr);

}  // namespace hybrid_vo
