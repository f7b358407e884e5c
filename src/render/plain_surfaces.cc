#include "plain_surfaces.h"

#include <algorithm>
#include <cmath>

namespace hybrid_vo {
namespace render {
namespace {

// Albedo steps between neighbouring plain surfaces: about 5-15 grey levels once lit.
constexpr double kWallMin = 0.78, kWallMax = 0.86;
constexpr double kFloor = 0.46, kFloorJoint = 0.40;
constexpr double kCeiling = 0.80, kLightPanel = 0.90;
constexpr double kJointSpacing = 2.0, kJointWidth = 0.015;  // metres

bool overlaps(const std::vector<std::pair<double, double>>& intervals, double a, double b) {
  for (const auto& [lo, hi] : intervals)
    if (a < hi && b > lo) return true;
  return false;
}

}  // namespace

void paint_plain_wall(Canvas* c, const WallLayout& layout, Rng& rng,
                      std::vector<Eigen::Vector2d>* corners) {
  const double L = layout.length, H = layout.height;
  const double paint = rng.uniform(kWallMin, kWallMax);
  c->rect(0.0, 0.0, L, H, paint);
  // Doors every 3-6 m where no box stands: a frame 7 cm wide around a leaf. Heights are above
  // the floor; the canvas's v runs down from the top of the wall.
  const double arch = 0.07, top = std::min(2.1, H - 0.3);
  const double frame = paint - 0.07, leaf = paint - 0.03;
  for (double u = rng.uniform(1.0, 3.0);; u += rng.uniform(3.0, 6.0)) {
    const double width = rng.uniform(0.8, 1.0);
    const double u1 = u + width + 2.0 * arch;
    if (u1 > L - 0.5) break;
    if (overlaps(layout.blocked, u - 0.2, u1 + 0.2)) continue;
    c->rect(u, H - (top + arch), u1, H, frame);
    c->rect(u + arch, H - top, u1 - arch, H, leaf);
    for (const double corner_u : {u, u1}) corners->emplace_back(c->snap(corner_u), c->snap(H - top - arch));
  }
}

void paint_plain_floor(Canvas* c, const Quad& quad, uint64_t seed) {
  const double x0 = quad.origin.x(), x1 = x0 + quad.size_u;
  const double y1 = quad.origin.y(), y0 = y1 - quad.size_v;
  c->rect(0.0, 0.0, quad.size_u, quad.size_v, kFloor);
  // The grid's phase is the scene's, so that the joints continue across quads.
  Rng rng(seed);
  const double phase_x = rng.uniform(0.0, kJointSpacing), phase_y = rng.uniform(0.0, kJointSpacing);
  const double h = 0.5 * kJointWidth;
  for (double x = phase_x + kJointSpacing * std::floor((x0 - phase_x) / kJointSpacing); x <= x1;
       x += kJointSpacing)
    c->rect(x - h - x0, 0.0, x + h - x0, quad.size_v, kFloorJoint);
  for (double y = phase_y + kJointSpacing * std::floor((y0 - phase_y) / kJointSpacing); y <= y1;
       y += kJointSpacing)
    c->rect(0.0, y1 - (y + h), quad.size_u, y1 - (y - h), kFloorJoint);
}

void paint_plain_ceiling(Canvas* c, const Quad& quad, const std::vector<Light>& lights) {
  const double x0 = quad.origin.x(), y0 = quad.origin.y();
  c->rect(0.0, 0.0, quad.size_u, quad.size_v, kCeiling);
  for (const Light& light : lights) {
    const Eigen::Vector2d lo = light.position.head<2>() - light.half_extent - Eigen::Vector2d(x0, y0);
    const Eigen::Vector2d hi = light.position.head<2>() + light.half_extent - Eigen::Vector2d(x0, y0);
    c->rect(lo.x(), lo.y(), hi.x(), hi.y(), kLightPanel);
  }
}

double plain_box_albedo(uint64_t seed) {
  Rng rng(seed);
  const double step = rng.uniform(0.04, 0.08);
  return 0.5 * (kWallMin + kWallMax) + (rng.chance(0.5) ? step : -step);
}

}  // namespace render
}  // namespace hybrid_vo
