#include "hybrid_vo/odometry/cpu_budget.h"

#include <algorithm>
#include <cmath>

namespace hybrid_vo {
namespace {

// The exponential average's weight of a new frame: about the last five frames count.
constexpr double kNewFrameWeight = 0.2;

}  // namespace

CpuBudget::CpuBudget(const CpuBudgetOptions& options) : options_(options) {
  floor_ = std::clamp(options_.min_work_level, 0, kMaxWorkLevel);
  reset();
}

void CpuBudget::reset() {
  level_ = floor_;
  average_ = 0.0;
  seen_ = false;
  since_step_ = 0;
  fitting_below_ = 0;
}

int CpuBudget::update(double cpu_ms) {
  if (!std::isfinite(cpu_ms) || cpu_ms < 0.0) return level_;
  average_ = seen_ ? average_ + kNewFrameWeight * (cpu_ms - average_) : cpu_ms;
  seen_ = true;
  ++since_step_;
  const double budget = options_.max_cpu_ms;
  if (!(budget > 0.0)) return level_;
  if (average_ > budget) {
    fitting_below_ = 0;
    if (level_ < kMaxWorkLevel && since_step_ >= kSettleFrames) {
      ++level_;
      since_step_ = 0;
      // The average so far was paid at the level below: start this level's from its prediction.
      average_ *= kCostRatio[level_];
    }
    return level_;
  }
  if (level_ > floor_ && average_ / kCostRatio[level_] < kStepDownMargin * budget) {
    if (++fitting_below_ >= kStepDownFrames) {
      average_ /= kCostRatio[level_];
      --level_;
      since_step_ = 0;
      fitting_below_ = 0;
    }
  } else {
    fitting_below_ = 0;
  }
  return level_;
}

}  // namespace hybrid_vo
