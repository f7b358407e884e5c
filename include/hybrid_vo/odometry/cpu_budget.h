#pragma once

#include <array>

#include "hybrid_vo/geometry/option_fields.h"

namespace hybrid_vo {

// How much of the front end's optional work a frame does. Each level drops, on top of the one
// below it, the work that bought the least accuracy per millisecond on the evaluation sets
// (doc/performance.md, "A CPU budget"):
//   0 everything;
//   1 KLT re-detection in half the grid's cells per frame, taking turns (redetect_alternate);
//   2 a KLT grid cell is re-detected only once it misses half its quota, and lost segment tracks
//     are not re-identified by their descriptors;
//   3 segments get no LBD descriptor (a track with two parallel candidates is left unmatched;
//     without segment tracking they keep them: they are what matches the segments);
//   4 half the point features.
constexpr int kMaxWorkLevel = 4;

struct CpuBudgetOptions {
  // CPU milliseconds per frame, both threads added; 0: no budget (the level stays at
  // min_work_level).
  double max_cpu_ms = 0.0;
  // The lowest level the budget may choose, 0..kMaxWorkLevel: a fixed level without a budget.
  int min_work_level = 0;
};

template <typename Visit>
void visit_fields(CpuBudgetOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(non_negative(), o.max_cpu_ms);
  visit("min_work_level", o.min_work_level, between(0.0, kMaxWorkLevel));
}

// Chooses each frame's work level from the CPU time of the frames before: one level up when the
// recent frames' mean (an exponential average over about five frames) exceeds the budget, one
// down when the level below is predicted to fit with a margin, each step only after the last
// one had time to show. Frames that cost nothing (the first, a reset) count as they come.
class CpuBudget {
 public:
  // What a level costs against the one below it, measured on the evaluation sets; the
  // prediction of the level below is the average divided by it.
  static constexpr std::array<double, kMaxWorkLevel + 1> kCostRatio = {1.0, 0.80, 0.85, 0.85,
                                                                        0.75};
  static constexpr int kSettleFrames = 5;    // frames after a step before the next one up
  static constexpr int kStepDownFrames = 30;  // frames the level below must fit before a step down
  static constexpr double kStepDownMargin = 0.85;  // of the budget, for the level below

  explicit CpuBudget(const CpuBudgetOptions& options = {});
  // The level for the next frame, after a frame that took `cpu_ms` (both threads); a value that
  // is not finite or negative is ignored.
  int update(double cpu_ms);
  int level() const { return level_; }
  // The exponential average of the frames' CPU time (ms); 0 before the first frame.
  double average_cpu_ms() const { return average_; }
  void reset();

 private:
  CpuBudgetOptions options_;
  int floor_ = 0;
  int level_ = 0;
  double average_ = 0.0;
  bool seen_ = false;
  int since_step_ = 0;
  int fitting_below_ = 0;
};

}  // namespace hybrid_vo
