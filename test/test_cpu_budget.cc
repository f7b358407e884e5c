// The CPU budget's controller (odometry/cpu_budget.h): no budget keeps the fixed level; frames
// over the budget raise the level a step at a time, each after the last had time to show; frames
// that would fit the level below lower it again after a while; nonsense times are ignored.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "hybrid_vo/odometry/cpu_budget.h"

namespace {

using hybrid_vo::CpuBudget;
using hybrid_vo::CpuBudgetOptions;
using hybrid_vo::kMaxWorkLevel;

// Feeds `frames` frames of `cpu_ms(level)` and returns the level after them.
template <class Cost>
int feed(CpuBudget* budget, int frames, Cost cpu_ms) {
  for (int i = 0; i < frames; ++i) budget->update(cpu_ms(budget->level()));
  return budget->level();
}

TEST(CpuBudget, WithoutABudgetTheLevelStaysAtItsFloor) {
  for (int floor : {0, 2, kMaxWorkLevel}) {
    CpuBudgetOptions options;
    options.min_work_level = floor;
    CpuBudget budget(options);
    EXPECT_EQ(budget.level(), floor);
    EXPECT_EQ(feed(&budget, 50, [](int) { return 1000.0; }), floor);
    EXPECT_NEAR(budget.average_cpu_ms(), 1000.0, 1e-9);
  }
  CpuBudgetOptions beyond;
  beyond.min_work_level = 7;  // the node rejects it (its bounds); the controller clamps it
  EXPECT_EQ(CpuBudget(beyond).level(), kMaxWorkLevel);
}

TEST(CpuBudget, OverTheBudgetItStepsUpOneLevelAtATime) {
  CpuBudgetOptions options;
  options.max_cpu_ms = 10.0;
  CpuBudget budget(options);
  // The first frames over the budget: up one level once the settling frames are over, not before.
  EXPECT_EQ(feed(&budget, CpuBudget::kSettleFrames - 1, [](int) { return 30.0; }), 0);
  EXPECT_EQ(feed(&budget, 1, [](int) { return 30.0; }), 1);
  EXPECT_EQ(feed(&budget, 1, [](int) { return 30.0; }), 1);
  // Always over: the lightest level, and no further.
  EXPECT_EQ(feed(&budget, 100, [](int) { return 30.0; }), kMaxWorkLevel);
}

TEST(CpuBudget, ItSettlesWhereTheLevelFitsAndStepsBackWhenTheLoadGoes) {
  CpuBudgetOptions options;
  options.max_cpu_ms = 20.0;
  CpuBudget budget(options);
  // Each level costs what the controller expects of it, 30 ms with all the work.
  auto cost = [](double full) {
    return [full](int level) {
      double c = full;
      for (int l = 1; l <= level; ++l) c *= CpuBudget::kCostRatio[l];
      return c;
    };
  };
  int fits = 0;  // the first level within the budget
  while (fits < kMaxWorkLevel && cost(30.0)(fits) > options.max_cpu_ms) ++fits;
  ASSERT_GT(fits, 1);
  EXPECT_EQ(feed(&budget, 200, cost(30.0)), fits);
  EXPECT_EQ(feed(&budget, 200, cost(30.0)), fits);  // and stays there
  // The load goes (a quarter of it is left): all the work again, and it stays there.
  EXPECT_EQ(feed(&budget, 400, cost(7.5)), 0);
  EXPECT_EQ(feed(&budget, 200, cost(7.5)), 0);
}

TEST(CpuBudget, TimesThatAreNotFiniteOrNegativeAreIgnored) {
  CpuBudgetOptions options;
  options.max_cpu_ms = 10.0;
  CpuBudget budget(options);
  budget.update(5.0);
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity(), -3.0})
    for (int i = 0; i < 20; ++i) budget.update(bad);
  EXPECT_EQ(budget.level(), 0);
  EXPECT_NEAR(budget.average_cpu_ms(), 5.0, 1e-12);
  budget.reset();
  EXPECT_EQ(budget.average_cpu_ms(), 0.0);
}

}  // namespace
