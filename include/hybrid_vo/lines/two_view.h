#pragma once

#include "hybrid_vo/estimation/relative_pose_estimator.h"
#include "hybrid_vo/lines/vp_detection.h"

namespace hybrid_vo {

struct TwoViewOptions {
  RelativePoseEstimatorOptions estimator;
  // When the matches carry no VPs and a VP solver is enabled, detect them from the line matches.
  bool detect_vps = true;
  bool joint_vp_detection = true;  // false: the per-image "standard" baseline
  VpDetectionOptions vp_detection;

  // VPs for pose estimation need more support than the detector's default: on TUM, VP matches
  // with fewer than 20 segments agreed with the ground-truth rotation (2 degrees) in under half
  // of the cases, and they cost the hybrid presets up to 8 AUC@10 points (README, pair
  // evaluation). The VO node sets its own (vp_min_inliers).
  TwoViewOptions() { vp_detection.min_inliers = 15; }
};

struct TwoViewEstimate {
  RelativePoseEstimate estimate;
  bool vps_detected = false;
  MatchedVps vps;  // the detected VPs and labels, when detected
  double vp_ms = 0.0;
};

// The estimator with VP detection in front (DESIGN.md, "Estimation": VPs come from the joint
// detector when they are not given). Given VPs and labels are used as they are.
TwoViewEstimate estimate_two_view(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                  const TwoViewMatches& matches, const TwoViewOptions& options = {});

}  // namespace hybrid_vo
