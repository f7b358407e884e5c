#include "hybrid_vo/datasets/point_subset.h"

#include <algorithm>
#include <numeric>
#include <random>

namespace hybrid_vo {
namespace datasets {

bool parse_point_selection(const std::string& text, PointSelection* selection) {
  if (text == "random") *selection = PointSelection::kRandom;
  else if (text == "clustered") *selection = PointSelection::kClustered;
  else return false;
  return true;
}

const char* to_string(PointSelection selection) {
  return selection == PointSelection::kRandom ? "random" : "clustered";
}

std::vector<int> select_point_matches(const std::vector<PointMatch>& points, int max_points,
                                      PointSelection selection, uint64_t seed) {
  const int n = static_cast<int>(points.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (max_points < 0 || max_points >= n) return order;
  // Its own stream: the caller's seed also seeds RANSAC, which must not see the same numbers.
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ull);
  if (selection == PointSelection::kRandom) {
    std::shuffle(order.begin(), order.end(), rng);
  } else {
    const int centre = static_cast<int>(std::uniform_int_distribution<int>(0, n - 1)(rng));
    const Eigen::Vector2d c = points[centre].x1;
    std::vector<double> distance(n);
    for (int i = 0; i < n; ++i) distance[i] = (points[i].x1 - c).squaredNorm();
    // Ties (duplicate positions) break by index, so the order is deterministic.
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return distance[a] < distance[b]; });
  }
  order.resize(max_points);
  std::sort(order.begin(), order.end());
  return order;
}

}  // namespace datasets
}  // namespace hybrid_vo
