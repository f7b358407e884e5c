#include "hybrid_vo/estimation/modality_scales.h"

#include <algorithm>
#include <cmath>

namespace hybrid_vo {

double robust_sigma(std::vector<double>* magnitudes, int axes) {
  std::vector<double>& v = *magnitudes;
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }),
          v.end());
  if (v.empty()) return 0.0;
  for (double& x : v) x = std::abs(x);
  const size_t half = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + half, v.end());
  double median = v[half];
  if (v.size() % 2 == 0) median = 0.5 * (median + *std::max_element(v.begin(), v.begin() + half));
  // Medians of |N(0,1)| and of the Rayleigh distribution with unit per-axis sigma.
  const double unit_median = axes == 2 ? std::sqrt(2.0 * std::log(2.0)) : 0.674489750196082;
  return median / unit_median;
}

}  // namespace hybrid_vo
