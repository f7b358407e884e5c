#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace hybrid_vo {

// Percentiles of the last `size` samples (e.g. a frame's time from arrival to publication), for
// diagnostics: a bounded window, so that an hour-long run costs the same as a minute.
class LatencyWindow {
 public:
  explicit LatencyWindow(size_t size = 200) : size_(size < 1 ? 1 : size) {}

  void add(double value) {
    if (samples_.size() < size_) {
      samples_.push_back(value);
    } else {
      samples_[next_] = value;
      next_ = (next_ + 1) % size_;
    }
  }

  // The q-quantile (0..1, nearest rank) of the window; 0 without samples.
  double quantile(double q) const {
    if (samples_.empty()) return 0.0;
    std::vector<double> sorted = samples_;
    const size_t k = std::min(sorted.size() - 1,
                              static_cast<size_t>(std::max(0.0, q) * (sorted.size() - 1) + 0.5));
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    return sorted[k];
  }
  size_t count() const { return samples_.size(); }

 private:
  size_t size_;
  size_t next_ = 0;
  std::vector<double> samples_;
};

}  // namespace hybrid_vo
