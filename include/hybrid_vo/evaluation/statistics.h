#pragma once

// Small statistics shared by the benchmarks and evaluations (header-only: the tools link
// different libraries).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace hybrid_vo {
namespace evaluation {

// The upper median (the middle element; of two middles the higher); NaN when empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The p-quantile (0..1) by the nearest rank; NaN when empty.
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

// A difference of a statistic between two methods with its bootstrap interval.
struct DifferenceInterval {
  double difference = NAN;   // statistic(b) - statistic(a) on the data as measured
  double low = NAN, high = NAN;  // the central `level` percentile interval of the resamples
  int groups = 0;
};

// Paired bootstrap of statistic(b) - statistic(a) over groups: a[i] and b[i] are the two methods'
// values on the same item, and items come in consecutive groups of `group_size` (e.g. one image
// pair's RANSAC runs) that are resampled together, because the runs of one pair share its
// difficulty and are not independent samples. It says whether a difference holds across the
// pairs or rests on a few of them (on TUM's 16 pairs, a few AUC points can); RANSAC's run-to-run
// noise is not in it. NaN (groups 0) when the sizes differ, are empty, or are not a multiple of
// group_size.
template <class Statistic>
DifferenceInterval paired_bootstrap_difference(const std::vector<double>& a,
                                               const std::vector<double>& b, int group_size,
                                               Statistic statistic, int resamples = 2000,
                                               uint64_t seed = 0, double level = 0.95) {
  DifferenceInterval out;
  if (a.size() != b.size() || a.empty() || group_size <= 0 || a.size() % group_size != 0 ||
      resamples <= 0)
    return out;
  const int groups = static_cast<int>(a.size() / group_size);
  out.groups = groups;
  out.difference = statistic(b) - statistic(a);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, groups - 1);
  std::vector<double> differences(resamples), ra, rb;
  for (double& d : differences) {
    ra.clear();
    rb.clear();
    for (int g = 0; g < groups; ++g) {
      const size_t first = static_cast<size_t>(pick(rng)) * group_size;
      ra.insert(ra.end(), a.begin() + first, a.begin() + first + group_size);
      rb.insert(rb.end(), b.begin() + first, b.begin() + first + group_size);
    }
    d = statistic(rb) - statistic(ra);
  }
  const double tail = 0.5 * (1.0 - std::clamp(level, 0.0, 1.0));
  out.low = percentile(differences, tail);
  out.high = percentile(differences, 1.0 - tail);
  return out;
}

}  // namespace evaluation
}  // namespace hybrid_vo
