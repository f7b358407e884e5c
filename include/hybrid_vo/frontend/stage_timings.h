#pragma once

#include <chrono>

namespace hybrid_vo {

// Where a frame's time goes: wall-clock milliseconds of each stage of VisualOdometry::process.
// The segments and the stereo matching run on a second thread beside the points and the
// estimator, so the stages overlap and need not add up to the frame's total.
struct StageTimings {
  double points_ms = 0.0;         // KLT tracking (or detection + description)
  double redetect_ms = 0.0;       // KLT re-detection for the next frame (second thread)
  double lines_ms = 0.0;          // segment detection and LBD description (second thread)
  double line_matching_ms = 0.0;  // segment tracking or matching against the keyframe
  double vps_ms = 0.0;            // joint VP detection and the VP tracker
  double ransac_ms = 0.0;         // hybrid RANSAC and the final refinement
  double stereo_ms = 0.0;         // stereo matching of the frame's points (second thread)
  double scale_ms = 0.0;          // stereo scale: its points' affine refinement and the fit
};

// Milliseconds since `start`.
inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace hybrid_vo
