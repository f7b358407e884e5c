#pragma once

#include <cstdint>
#include <vector>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {
namespace evaluation {

struct OpenCvPose {
  bool ok = false;
  RelativePose pose;          // X2 = R X1 + t, unit t
  // MAGSAC's mask, before recoverPose's cheirality pruning; all zero unless ok.
  std::vector<char> inliers;
};

// The baseline both benchmarks compare against: cv::findEssentialMat called as a user would
// (pixels, K, threshold in pixels) with the settings of its USAC_MAGSAC flag, then
// cv::recoverPose. The seed is ours: the flag version always seeds 0, so repeated runs on one
// pair would be one run.
OpenCvPose opencv_usac_magsac(const std::vector<PointMatch>& matches, const PinholeCamera& camera1,
                              const PinholeCamera& camera2, double threshold_px, uint64_t seed);

}  // namespace evaluation
}  // namespace hybrid_vo
