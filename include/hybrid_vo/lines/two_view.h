#pragma once

#include "hybrid_vo/estimation/relative_pose_estimator.h"
#include "hybrid_vo/lines/vp_detection.h"

namespace hybrid_vo {

// The estimator's options with the VP detection in front of it, on one level: the estimator's
// fields (ransac, junctions, ...) are TwoViewOptions' own.
struct TwoViewOptions : RelativePoseEstimatorOptions {
  // When the matches carry no VPs and a VP solver is enabled, detect them from the line matches.
  bool detect_vps = true;
  bool joint_vp_detection = true;  // false: the per-image "standard" baseline
  VpDetectionOptions vp_detection;

  // VPs for pose estimation need more support than the detector's default: on TUM, VP matches
  // with fewer than 20 segments agreed with the ground-truth rotation (2 degrees) in under half
  // of the cases, and they cost the hybrid presets up to 8 AUC@10 points (doc/pairs.md, pair
  // evaluation). The VO node sets its own (vp_min_inliers).
  TwoViewOptions() { vp_detection.min_inliers = 15; }
};

// The estimator's fields, then the detection's under vp_detection_ (its seed is the RANSAC's).
template <typename Visit>
void visit_fields(TwoViewOptions& o, Visit&& visit) {
  visit_fields(static_cast<RelativePoseEstimatorOptions&>(o), visit);
  HYBRID_VO_FIELDS(any_value(), o.detect_vps, o.joint_vp_detection);
  visit_fields(o.vp_detection, prefixed("vp_detection_", visit, {"seed"}));
}

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
