#include "hybrid_vo/estimation/derived_matches.h"

#include <algorithm>
#include <cmath>

namespace hybrid_vo {
namespace {

struct SegmentGeometry {
  Eigen::Vector2d origin, direction;  // unit direction
  double length = 0.0;
};

SegmentGeometry geometry_of(const LineSegment& s) {
  SegmentGeometry g;
  g.origin = s.p1;
  g.length = s.length();
  g.direction = (s.p2 - s.p1) / g.length;
  return g;
}

// Intersection of two segments' lines when it lies on both (within each one's tolerance past an
// end) and they cross at an angle whose sine is at least `min_sin`.
bool intersect_segments(const SegmentGeometry& a, const SegmentGeometry& b,
                        const JunctionOptions& options, double min_sin, Eigen::Vector2d* x) {
  const double cross = a.direction.x() * b.direction.y() - a.direction.y() * b.direction.x();
  if (std::abs(cross) < min_sin) return false;
  const Eigen::Vector2d d = b.origin - a.origin;
  const double ta = (d.x() * b.direction.y() - d.y() * b.direction.x()) / cross;
  const double tb = (d.x() * a.direction.y() - d.y() * a.direction.x()) / cross;
  const double tolerance_a = junction_tolerance_px(a.length, std::abs(cross), options);
  const double tolerance_b = junction_tolerance_px(b.length, std::abs(cross), options);
  if (ta < -tolerance_a || ta > a.length + tolerance_a) return false;
  if (tb < -tolerance_b || tb > b.length + tolerance_b) return false;
  *x = a.origin + ta * a.direction;
  return true;
}

}  // namespace

double junction_tolerance_px(double length, double sin_angle, const JunctionOptions& options) {
  const double grown = options.length_fraction * length * sin_angle;
  return std::max(options.tolerance_px, std::min(grown, options.max_tolerance_px));
}

bool valid_segment(const LineSegment& s, double min_length) {
  return all_finite(s.p1) && all_finite(s.p2) && s.length() > min_length;
}

std::vector<DerivedPoint> find_junctions(const std::vector<LineMatch>& lines,
                                         const JunctionOptions& options) {
  const int n = static_cast<int>(lines.size());
  std::vector<char> valid(n);
  std::vector<SegmentGeometry> g1(n), g2(n);
  for (int i = 0; i < n; ++i) {
    valid[i] = valid_segment(lines[i].s1) && valid_segment(lines[i].s2);
    if (!valid[i]) continue;
    g1[i] = geometry_of(lines[i].s1);
    g2[i] = geometry_of(lines[i].s2);
  }
  const double min_sin = std::sin(options.min_angle_deg * M_PI / 180.0);
  std::vector<DerivedPoint> junctions;
  for (int i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    for (int j = i + 1; j < n; ++j) {
      if (!valid[j]) continue;
      DerivedPoint jp;
      if (!intersect_segments(g1[i], g1[j], options, min_sin, &jp.match.x1)) continue;
      if (!intersect_segments(g2[i], g2[j], options, min_sin, &jp.match.x2)) continue;
      jp.source = PointSource::kJunction;
      jp.first = i;
      jp.second = j;
      junctions.push_back(jp);
    }
  }
  return junctions;
}

std::vector<int> distinct_junctions(const std::vector<DerivedPoint>& junctions, double radius_px) {
  std::vector<int> kept;
  const double radius_sq = radius_px > 0.0 ? radius_px * radius_px : -1.0;
  for (int i = 0; i < static_cast<int>(junctions.size()); ++i) {
    const PointMatch& m = junctions[i].match;
    bool repeats = false;
    for (const int k : kept) {
      const PointMatch& n = junctions[k].match;
      if ((n.x1 - m.x1).squaredNorm() <= radius_sq || (n.x2 - m.x2).squaredNorm() <= radius_sq) {
        repeats = true;
        break;
      }
    }
    if (!repeats) kept.push_back(i);
  }
  return kept;
}

std::vector<DerivedPoint> segment_endpoints(const std::vector<LineMatch>& lines) {
  std::vector<DerivedPoint> endpoints;
  for (int i = 0; i < static_cast<int>(lines.size()); ++i) {
    const LineSegment &a = lines[i].s1, &b = lines[i].s2;
    if (!valid_segment(a) || !valid_segment(b)) continue;
    const bool same_way = (a.p2 - a.p1).dot(b.p2 - b.p1) >= 0.0;
    for (int end = 0; end < 2; ++end) {
      DerivedPoint p;
      p.source = PointSource::kEndpoint;
      p.first = i;
      p.second = end;
      p.match.x1 = end == 0 ? a.p1 : a.p2;
      p.match.x2 = (end == 0) == same_way ? b.p1 : b.p2;
      endpoints.push_back(p);
    }
  }
  return endpoints;
}

}  // namespace hybrid_vo
