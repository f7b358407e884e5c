#include "hybrid_vo/frontend/line_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace hybrid_vo {
namespace {

// Point matches bucketed by their keyframe position, for nearest-neighbour queries.
class PointGrid {
 public:
  PointGrid(const std::vector<PointMatch>& matches, double cell) : matches_(matches), cell_(cell) {
    for (size_t k = 0; k < matches.size(); ++k) {
      if (!all_finite(matches[k].x1) || !all_finite(matches[k].x2)) continue;
      cells_[key(cell_index(matches[k].x1.x()), cell_index(matches[k].x1.y()))].push_back(
          static_cast<int>(k));
    }
  }

  // Indices of the (up to) k nearest matches within `radius` of p, nearest first.
  std::vector<int> nearest(const Eigen::Vector2d& p, int k, double radius) const {
    std::vector<std::pair<double, int>> found;
    const int cx = cell_index(p.x()), cy = cell_index(p.y());
    const int reach = static_cast<int>(std::ceil(radius / cell_));
    for (int y = cy - reach; y <= cy + reach; ++y) {
      for (int x = cx - reach; x <= cx + reach; ++x) {
        const auto it = cells_.find(key(x, y));
        if (it == cells_.end()) continue;
        for (int m : it->second) {
          const double d = (matches_[m].x1 - p).squaredNorm();
          if (d <= radius * radius) found.emplace_back(d, m);
        }
      }
    }
    const size_t count = std::min(found.size(), static_cast<size_t>(std::max(k, 0)));
    std::partial_sort(found.begin(), found.begin() + count, found.end());
    std::vector<int> out(count);
    for (size_t r = 0; r < count; ++r) out[r] = found[r].second;
    return out;
  }

 private:
  int cell_index(double v) const { return static_cast<int>(std::floor(v / cell_)); }
  static int64_t key(int x, int y) {
    return (static_cast<int64_t>(x) << 32) ^ static_cast<int64_t>(static_cast<uint32_t>(y));
  }

  const std::vector<PointMatch>& matches_;
  double cell_;
  std::unordered_map<int64_t, std::vector<int>> cells_;
};

double median_of(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Where `p` moves: the median motion of its neighbours, and the spread of their motions (median
// distance from that median). False with fewer than min_neighbours.
bool predict_point(const PointGrid& grid, const std::vector<PointMatch>& matches,
                   const Eigen::Vector2d& p, const LineTrackingOptions& options,
                   Eigen::Vector2d* moved, double* spread) {
  const std::vector<int> near =
      grid.nearest(p, options.neighbours, options.max_neighbour_distance_px);
  if (static_cast<int>(near.size()) < std::max(1, options.min_neighbours)) return false;
  std::vector<double> dx, dy;
  for (int m : near) {
    const Eigen::Vector2d d = matches[m].x2 - matches[m].x1;
    dx.push_back(d.x());
    dy.push_back(d.y());
  }
  const Eigen::Vector2d motion(median_of(dx), median_of(dy));
  std::vector<double> deviation;
  for (size_t r = 0; r < dx.size(); ++r)
    deviation.push_back((Eigen::Vector2d(dx[r], dy[r]) - motion).norm());
  *moved = p + motion;
  *spread = median_of(deviation);
  return true;
}

// A current segment near a prediction: its mean distance to the predicted endpoints and how much
// of the shorter of the two it overlaps.
struct Candidate {
  int j = 0;
  double offset = 0.0;
  double overlap = 0.0;
};

bool near_prediction(const LineSegment& predicted, const LineSegment& c, double tolerance,
                     double cos_max_angle, double min_overlap, Candidate* out) {
  const Eigen::Vector2d dp = predicted.p2 - predicted.p1, dc = c.p2 - c.p1;
  const double lp = dp.norm(), lc = dc.norm();
  if (!(lp > 0.0) || !(lc > 0.0)) return false;
  if (dp.dot(dc) < cos_max_angle * lp * lc) return false;
  const Eigen::Vector3d l = line_through(c.p1, c.p2);
  const double e1 = std::abs(l.dot(homogeneous(predicted.p1)));
  const double e2 = std::abs(l.dot(homogeneous(predicted.p2)));
  if (e1 > tolerance || e2 > tolerance) return false;
  const Eigen::Vector2d u = dc / lc;
  const double a = u.dot(predicted.p1 - c.p1), b = u.dot(predicted.p2 - c.p1);
  const double overlap = std::min(std::max(a, b), lc) - std::max(std::min(a, b), 0.0);
  if (overlap < min_overlap * std::min(std::abs(b - a), lc)) return false;
  out->offset = 0.5 * (e1 + e2);
  out->overlap = overlap;
  return true;
}

// Both segments on one line (within `tolerance` px): fragments of one edge.
bool same_line(const LineSegment& s, const LineSegment& t, double tolerance) {
  const Eigen::Vector3d ls = line_through(s.p1, s.p2), lt = line_through(t.p1, t.p2);
  return std::abs(ls.dot(homogeneous(t.p1))) <= tolerance &&
         std::abs(ls.dot(homogeneous(t.p2))) <= tolerance &&
         std::abs(lt.dot(homogeneous(s.p1))) <= tolerance &&
         std::abs(lt.dot(homogeneous(s.p2))) <= tolerance;
}

}  // namespace

std::vector<LineMatch> track_line_segments(const LineFeatures& keyframe,
                                           const LineFeatures& current,
                                           const std::vector<PointMatch>& point_matches,
                                           const LineMatchingOptions& matching,
                                           const LineTrackingOptions& options,
                                           LineTrackingStats* stats,
                                           std::vector<std::pair<int, int>>* pairs) {
  LineTrackingStats local_stats;
  LineTrackingStats& st = stats ? *stats : local_stats;
  st = LineTrackingStats();
  if (pairs) pairs->clear();
  std::vector<LineMatch> matches;
  const int n1 = static_cast<int>(keyframe.segments.size());
  const int n2 = static_cast<int>(current.segments.size());
  st.keyframe_segments = n1;
  if (n1 == 0 || n2 == 0) return matches;
  const bool descriptors = keyframe.descriptors.rows == n1 && current.descriptors.rows == n2 &&
                           keyframe.descriptors.cols == current.descriptors.cols &&
                           keyframe.descriptors.type() == current.descriptors.type();
  const double max_distance =
      descriptors ? max_line_descriptor_distance(matching, keyframe.descriptors) : 0.0;
  const double cos_max_angle = std::cos(options.max_angle_deg * M_PI / 180.0);

  // 1. Prediction and local search for every keyframe segment.
  const PointGrid grid(point_matches, std::max(1.0, options.max_neighbour_distance_px));
  std::vector<int> chosen(n1, -1);
  std::vector<double> score(n1, std::numeric_limits<double>::infinity());
  std::vector<Candidate> candidates;
  for (int i = 0; i < n1; ++i) {
    const LineSegment& s = keyframe.segments[i];
    LineSegment predicted;
    double spread1 = 0.0, spread2 = 0.0;
    if (!predict_point(grid, point_matches, s.p1, options, &predicted.p1, &spread1) ||
        !predict_point(grid, point_matches, s.p2, options, &predicted.p2, &spread2))
      continue;
    ++st.predicted;
    const double tolerance =
        options.max_offset_px + std::min(std::max(spread1, spread2), options.max_spread_px);
    candidates.clear();
    for (int j = 0; j < n2; ++j) {
      Candidate c;
      c.j = j;
      if (near_prediction(predicted, current.segments[j], tolerance, cos_max_angle,
                          options.min_overlap, &c))
        candidates.push_back(c);
    }
    if (candidates.empty()) continue;
    // The best fit; other candidates on its line are fragments of the same edge, the longest
    // overlap of which is kept.
    const auto best = std::min_element(candidates.begin(), candidates.end(),
                                       [](const Candidate& a, const Candidate& b) {
                                         return a.offset < b.offset;
                                       });
    const LineSegment& best_segment = current.segments[best->j];
    bool ambiguous = false;
    Candidate pick = *best;
    for (const Candidate& c : candidates) {
      if (c.j == best->j) continue;
      if (!same_line(best_segment, current.segments[c.j], options.max_offset_px)) {
        ambiguous = true;
        break;
      }
      if (c.overlap > pick.overlap) pick = c;
    }
    if (ambiguous) {
      // Parallel edges near the prediction: the descriptor decides.
      if (!descriptors) continue;
      float d_best = std::numeric_limits<float>::infinity();
      float d_second = std::numeric_limits<float>::infinity();
      int j_best = -1;
      for (const Candidate& c : candidates) {
        const float d =
            line_descriptor_distance(keyframe.descriptors, i, current.descriptors, c.j);
        if (d < d_best) {
          d_second = d_best;
          d_best = d;
          j_best = c.j;
        } else if (d < d_second) {
          d_second = d;
        }
      }
      if (j_best < 0 || d_best > max_distance ||
          (std::isfinite(d_second) && d_best >= options.ratio * d_second))
        continue;
      pick = *std::find_if(candidates.begin(), candidates.end(),
                           [&](const Candidate& c) { return c.j == j_best; });
      ++st.ambiguous;
    }
    chosen[i] = pick.j;
    score[i] = pick.offset;
  }

  // 2. A current segment claimed by several keyframe segments goes to the best fit, and to the
  //    others only when they are fragments of the same keyframe edge.
  std::vector<int> owner(n2, -1);
  for (int i = 0; i < n1; ++i) {
    if (chosen[i] < 0) continue;
    int& o = owner[chosen[i]];
    if (o < 0 || score[i] < score[o]) o = i;
  }
  std::vector<char> taken(n2, 0);
  for (int i = 0; i < n1; ++i) {
    if (chosen[i] < 0) continue;
    const int o = owner[chosen[i]];
    if (o != i && !same_line(keyframe.segments[o], keyframe.segments[i], options.max_offset_px)) {
      chosen[i] = -1;
      continue;
    }
    taken[chosen[i]] = 1;
  }
  for (int i = 0; i < n1; ++i) {
    if (chosen[i] < 0) continue;
    matches.push_back({keyframe.segments[i], current.segments[chosen[i]]});
    if (pairs) pairs->emplace_back(i, chosen[i]);
    ++st.tracked;
  }

  // 3. The segments the search lost: full LBD matching, kept for them and free current segments.
  if (options.descriptor_fallback && descriptors &&
      std::count(chosen.begin(), chosen.end(), -1) > 0) {
    std::vector<std::pair<int, int>> lbd_pairs;
    match_line_features(keyframe, current, matching, &lbd_pairs);
    for (const auto& [i, j] : lbd_pairs) {
      if (chosen[i] >= 0 || taken[j]) continue;
      matches.push_back({keyframe.segments[i], current.segments[j]});
      if (pairs) pairs->emplace_back(i, j);
      ++st.fallback;
    }
  }
  return matches;
}

}  // namespace hybrid_vo
