#pragma once

#include <cstdlib>
#include <vector>

namespace hybrid_vo {

// A deliberate leak, so that the soak can show it tells a leak from a bounded buffer filling up
// (scripts/soak --leak BYTES, doc/reliability.md). Only when the environment variable
// HYBRID_VO_SOAK_LEAK_BYTES is set does every processed frame keep that many bytes for good;
// unset, as everywhere outside that test, it keeps nothing.
class InjectedLeak {
 public:
  InjectedLeak() {
    if (const char* bytes = std::getenv("HYBRID_VO_SOAK_LEAK_BYTES"))
      bytes_per_frame_ = std::strtoul(bytes, nullptr, 10);
  }

  void on_frame() {
    // Filled, so that the pages are touched and count in the resident set.
    if (bytes_per_frame_ > 0) kept_.emplace_back(bytes_per_frame_, '\1');
  }

 private:
  size_t bytes_per_frame_ = 0;
  std::vector<std::vector<char>> kept_;
};

}  // namespace hybrid_vo
