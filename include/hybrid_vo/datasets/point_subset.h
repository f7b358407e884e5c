#pragma once

// The few-points regime of the pair evaluation: keep N of a pair's point matches, as a
// low-texture image would give them. Line matches are left as they are.

#include <cstdint>
#include <string>
#include <vector>

#include "hybrid_vo/estimation/matches.h"

namespace hybrid_vo {
namespace datasets {

enum class PointSelection {
  kRandom,     // N matches drawn uniformly: still spread over the whole image
  kClustered,  // the N matches nearest (in image 1) to one match drawn uniformly: one textured patch
};

// "random" / "clustered"; false for anything else.
bool parse_point_selection(const std::string& text, PointSelection* selection);
const char* to_string(PointSelection selection);

// Indices of the kept matches, in increasing order: exactly min(max_points, size) of them
// (every index when max_points < 0). The same seed gives the same subset, and for one seed the
// subset of a smaller N is contained in that of a larger N (one permutation, or one ordering by
// distance, cut at N), so that the rows of an evaluation differ only in N.
std::vector<int> select_point_matches(const std::vector<PointMatch>& points, int max_points,
                                      PointSelection selection, uint64_t seed);

}  // namespace datasets
}  // namespace hybrid_vo
