// The benchmarks' statistics (include/hybrid_vo/evaluation/statistics.h).

#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "hybrid_vo/evaluation/statistics.h"

namespace hybrid_vo {
namespace evaluation {
namespace {

double mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / v.size();
}

TEST(Statistics, MedianAndPercentile) {
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 3.0);  // the upper median
  EXPECT_TRUE(std::isnan(median({})));
  EXPECT_EQ(percentile({5.0, 1.0, 3.0}, 0.0), 1.0);
  EXPECT_EQ(percentile({5.0, 1.0, 3.0}, 1.0), 5.0);
}

TEST(Statistics, BootstrapOfAConstantShiftIsThatShift) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n;
  std::vector<double> a(60), b(60);
  for (size_t i = 0; i < a.size(); ++i) {
    a[i] = n(rng);
    b[i] = a[i] + 2.5;
  }
  const DifferenceInterval d = paired_bootstrap_difference(a, b, 3, mean);
  EXPECT_EQ(d.groups, 20);
  EXPECT_NEAR(d.difference, 2.5, 1e-12);
  EXPECT_NEAR(d.low, 2.5, 1e-12);
  EXPECT_NEAR(d.high, 2.5, 1e-12);
  const DifferenceInterval same = paired_bootstrap_difference(a, a, 3, mean);
  EXPECT_EQ(same.low, 0.0);
  EXPECT_EQ(same.high, 0.0);
}

// Differences of independent noise: the 95 % interval covers the true difference (0) in about
// 95 % of experiments, and its width shrinks like 1 / sqrt(groups).
TEST(Statistics, BootstrapIntervalHasItsCoverage) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> n;
  int covered = 0;
  double width_small = 0.0, width_large = 0.0;
  const int experiments = 200;
  for (int e = 0; e < experiments; ++e) {
    for (const int groups : {16, 64}) {
      std::vector<double> a(groups), b(groups);
      for (int i = 0; i < groups; ++i) {
        a[i] = n(rng);
        b[i] = n(rng);
      }
      const DifferenceInterval d = paired_bootstrap_difference(a, b, 1, mean, 500, e);
      if (groups == 16) {
        covered += d.low <= 0.0 && 0.0 <= d.high;
        width_small += d.high - d.low;
      } else {
        width_large += d.high - d.low;
      }
    }
  }
  EXPECT_GE(covered, 0.88 * experiments);
  EXPECT_LE(covered, experiments);
  // sqrt(64 / 16) = 2.
  EXPECT_NEAR(width_small / width_large, 2.0, 0.3);
  // A real difference of two standard errors of the 64-group mean is seen as one.
  std::vector<double> a(64), b(64);
  for (int i = 0; i < 64; ++i) {
    a[i] = n(rng);
    b[i] = a[i] + 1.0 + 0.1 * n(rng);
  }
  const DifferenceInterval shifted = paired_bootstrap_difference(a, b, 1, mean);
  EXPECT_GT(shifted.low, 0.9);
  EXPECT_LT(shifted.high, 1.1);
}

// A group's items move together: one group with a large difference among many without must give
// an interval that reaches zero, whatever the group's size.
TEST(Statistics, BootstrapResamplesWholeGroups) {
  std::vector<double> a(8 * 40, 0.0), b(8 * 40, 0.0);
  for (int i = 0; i < 40; ++i) b[i] = 10.0;  // group 0 only, all its 40 runs
  const DifferenceInterval d = paired_bootstrap_difference(a, b, 40, mean, 2000, 3);
  EXPECT_NEAR(d.difference, 10.0 / 8, 1e-12);
  EXPECT_EQ(d.low, 0.0);  // (7/8)^8 = 34 % of the resamples miss group 0
  EXPECT_GT(d.high, d.difference);
}

TEST(Statistics, BootstrapRejectsMismatchedInput) {
  const std::vector<double> a(12, 1.0), b(10, 1.0), empty;
  for (const DifferenceInterval& d :
       {paired_bootstrap_difference(a, b, 1, mean), paired_bootstrap_difference(a, a, 5, mean),
        paired_bootstrap_difference(a, a, 0, mean), paired_bootstrap_difference(a, a, 3, mean, 0),
        paired_bootstrap_difference(empty, empty, 1, mean)}) {
    EXPECT_EQ(d.groups, 0);
    EXPECT_TRUE(std::isnan(d.difference));
    EXPECT_TRUE(std::isnan(d.low));
    EXPECT_TRUE(std::isnan(d.high));
  }
}

}  // namespace
}  // namespace evaluation
}  // namespace hybrid_vo
