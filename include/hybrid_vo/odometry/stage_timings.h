#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <utility>

namespace hybrid_vo {

// Where a frame's time goes: wall-clock milliseconds of each stage of VisualOdometry::process.
// The stages run on two threads and overlap, so they need not add up to the frame's total. The
// KLT tracking, the stereo matching and the scale's refinement are shared by both threads (their
// time is the frame's wall clock while they run); the segments run on the second thread beside
// the KLT tracking, and the re-detection beside the estimator, on both threads (its time is the
// sum of its parts' on either).
struct StageTimings {
  double points_ms = 0.0;         // KLT tracking (or detection + description)
  double redetect_ms = 0.0;       // KLT re-detection for the next frame
  double lines_ms = 0.0;          // segment detection and LBD description (second thread)
  double line_matching_ms = 0.0;  // segment tracking or matching against the keyframe
  double vps_ms = 0.0;            // joint VP detection and the VP tracker
  double ransac_ms = 0.0;         // hybrid RANSAC and the final refinement
  double stereo_ms = 0.0;         // stereo matching of the frame's points
  double scale_ms = 0.0;          // stereo scale: its points' affine refinement and the fit
  // CPU time each thread spent on the frame (thread clocks; the worker's is 0 when sequential).
  // The longer of the two bounds the frame's time on two free cores.
  double caller_cpu_ms = 0.0, worker_cpu_ms = 0.0;
};

// Milliseconds since `start`.
inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The time of a stage whose parts run on several threads: the sum of the parts' wall clocks.
class WorkClock {
 public:
  // `body`, adding each call's time.
  template <class Body>
  std::function<void(int)> timed(Body body) {
    return [this, body = std::move(body)](int i) {
      const auto start = std::chrono::steady_clock::now();
      body(i);
      ns_ += std::chrono::duration_cast<std::chrono::nanoseconds>(
                 std::chrono::steady_clock::now() - start)
                 .count();
    };
  }
  double ms() const { return 1e-6 * static_cast<double>(ns_.load()); }

 private:
  std::atomic<int64_t> ns_{0};
};

}  // namespace hybrid_vo
