#include "hybrid_vo/direction_map/direction_structure.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

// The variance of a unit direction's angle towards `other`: its covariance along the tangent
// that points at `other`.
double variance_towards(const StructureDirection& d, const Eigen::Vector3d& other) {
  Eigen::Vector3d u = other - other.dot(d.direction) * d.direction;
  if (!(u.norm() > 1e-12)) return 0.0;
  u.normalize();
  return std::max(0.0, u.dot(d.covariance * u));
}

}  // namespace

bool DirectionStructure::is_orthogonal(int a, int b) const {
  for (const auto& pair : orthogonal)
    if ((pair[0] == a && pair[1] == b) || (pair[0] == b && pair[1] == a)) return true;
  return false;
}

double orthogonality_chi2(const StructureDirection& a, const StructureDirection& b,
                          double tolerance_deg) {
  const Eigen::Vector3d& u = a.direction;
  const Eigen::Vector3d& v = b.direction;
  // 90 degrees minus the angle between the lines, in [0, pi/2].
  const double deviation = std::atan2(std::abs(u.dot(v)), u.cross(v).norm());
  const double tolerance = tolerance_deg * kDeg;
  const double variance =
      variance_towards(a, v) + variance_towards(b, u) + tolerance * tolerance;
  if (!(variance > 0.0))
    return deviation > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
  return deviation * deviation / variance;
}

DirectionStructure find_structure(const std::vector<StructureDirection>& directions,
                                  const DirectionStructureOptions& options) {
  DirectionStructure s;
  const size_t n = directions.size();
  std::vector<std::vector<char>> orthogonal(n, std::vector<char>(n, 0));
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b)
      if (orthogonality_chi2(directions[a], directions[b], options.orthogonal_tolerance_deg) <=
          options.orthogonal_chi2) {
        orthogonal[a][b] = orthogonal[b][a] = 1;
        s.orthogonal.push_back({directions[a].id, directions[b].id});
      }
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b)
      for (size_t c = b + 1; c < n; ++c)
        if (orthogonal[a][b] && orthogonal[a][c] && orthogonal[b][c])
          s.triads.push_back({directions[a].id, directions[b].id, directions[c].id});
  for (size_t v = 0; v < n; ++v) {
    std::vector<size_t> horizontals;
    for (size_t h = 0; h < n; ++h)
      if (orthogonal[v][h]) horizontals.push_back(h);
    if (horizontals.empty()) ++s.free;
    // A vertical of an Atlanta world: two of its horizontals are not orthogonal to each other
    // (in a Manhattan triad each direction is orthogonal to the two others, which are).
    bool atlanta = false;
    for (size_t i = 0; i < horizontals.size() && !atlanta; ++i)
      for (size_t j = i + 1; j < horizontals.size() && !atlanta; ++j)
        atlanta = !orthogonal[horizontals[i]][horizontals[j]];
    if (atlanta) s.verticals.push_back(directions[v].id);
  }
  return s;
}

}  // namespace hybrid_vo
