#include "hybrid_vo/frontend/line_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hybrid_vo {
namespace {

// A detected segment near a prediction: the mean distance of the predicted endpoints to its line.
struct Candidate {
  int j = 0;
  double offset = 0.0;
};

bool near_prediction(const LineSegment& predicted, const LineSegment& c, double tolerance,
                     double cos_max_angle, double min_overlap, double* offset) {
  const Eigen::Vector2d dp = predicted.p2 - predicted.p1, dc = c.p2 - c.p1;
  const double lp = dp.norm(), lc = dc.norm();
  if (!(lp > 0.0) || !(lc > 0.0)) return false;
  if (dp.dot(dc) < cos_max_angle * lp * lc) return false;
  const Eigen::Vector3d l = line_through(c.p1, c.p2);
  const double e1 = std::abs(l.dot(homogeneous(predicted.p1)));
  const double e2 = std::abs(l.dot(homogeneous(predicted.p2)));
  if (!(e1 <= tolerance) || !(e2 <= tolerance)) return false;
  const Eigen::Vector2d u = dc / lc;
  const double a = u.dot(predicted.p1 - c.p1), b = u.dot(predicted.p2 - c.p1);
  const double overlap = std::min(std::max(a, b), lc) - std::max(std::min(a, b), 0.0);
  if (overlap < min_overlap * std::min(std::abs(b - a), lc)) return false;
  *offset = 0.5 * (e1 + e2);
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

double direction_angle(const LineSegment& s) {
  return std::atan2(s.p2.y() - s.p1.y(), s.p2.x() - s.p1.x());
}

double wrap_angle(double a) { return std::remainder(a, 2.0 * M_PI); }

}  // namespace

LineTracker::LineTracker(const LineTrackerOptions& options) : options_(options) {}

void LineTracker::reset() {
  tracks_.clear();
  started_ = false;
  now_ = 0.0;
}

LineSegment LineTracker::predict(const Track& t, double now) {
  if (!t.has_motion) return t.segment;
  const double dt = now - t.seen_at;
  const Eigen::Vector2d mid = t.segment.midpoint();
  const Eigen::Vector2d moved = mid + dt * t.shift;
  const Eigen::Rotation2Dd turn(dt * t.turn);
  return LineSegment(moved + turn * (t.segment.p1 - mid), moved + turn * (t.segment.p2 - mid));
}

std::vector<int64_t> LineTracker::track(const LineFeatures& current, double stamp,
                                        LineTrackingStats* stats) {
  LineTrackingStats local;
  LineTrackingStats& st = stats ? *stats : local;
  st = LineTrackingStats();
  // The clock: stamps when given; time going backwards starts afresh.
  const double now = std::isfinite(stamp) ? stamp : (started_ ? now_ + 1.0 : 0.0);
  if (started_ && now < now_) reset();
  started_ = true;
  now_ = now;
  st.tracks = static_cast<int>(tracks_.size());

  const int n = static_cast<int>(current.segments.size());
  const bool descriptors = current.descriptors.rows == n && n > 0;
  std::vector<int64_t> ids(n, -1);
  const int m = static_cast<int>(tracks_.size());
  std::vector<int> chosen(m, -1);
  std::vector<double> score(m, std::numeric_limits<double>::infinity());
  std::vector<Candidate> candidates;
  for (int k = 0; k < m; ++k) {
    const Track& t = tracks_[k];
    const LineSegment predicted = predict(t, now);
    const double motion = std::max((predicted.p1 - t.segment.p1).norm(),
                                   (predicted.p2 - t.segment.p2).norm());
    const double tolerance = t.has_motion
                                 ? options_.max_offset_px + options_.motion_fraction * motion
                                 : options_.max_offset_young_px;
    const double cos_angle = std::cos(
        (t.has_motion ? options_.max_angle_deg : options_.young_angle_deg) * M_PI / 180.0);
    candidates.clear();
    for (int j = 0; j < n; ++j) {
      Candidate c;
      c.j = j;
      if (near_prediction(predicted, current.segments[j], tolerance, cos_angle,
                          options_.min_overlap, &c.offset))
        candidates.push_back(c);
    }
    if (candidates.empty()) continue;
    const Candidate best = *std::min_element(
        candidates.begin(), candidates.end(),
        [](const Candidate& a, const Candidate& b) { return a.offset < b.offset; });
    bool ambiguous = false;
    for (const Candidate& c : candidates)
      if (c.j != best.j && !same_line(current.segments[best.j], current.segments[c.j],
                                      options_.max_offset_px))
        ambiguous = true;
    int pick = best.j;
    if (ambiguous) {
      // Parallel edges near the prediction: the descriptor decides, or nobody does.
      if (!descriptors || t.descriptor.empty()) continue;
      float d_best = std::numeric_limits<float>::infinity();
      float d_second = d_best;
      pick = -1;
      for (const Candidate& c : candidates) {
        const float d = line_descriptor_distance(t.descriptor, 0, current.descriptors, c.j);
        if (d < d_best) {
          d_second = d_best;
          d_best = d;
          pick = c.j;
        } else if (d < d_second) {
          d_second = d;
        }
      }
      if (pick < 0 || !(d_best <= options_.max_lbd_distance) ||
          (std::isfinite(d_second) && d_best >= options_.ratio * d_second))
        continue;
      ++st.ambiguous;
    }
    chosen[k] = pick;
    score[k] = std::find_if(candidates.begin(), candidates.end(),
                            [pick](const Candidate& c) { return c.j == pick; })
                   ->offset;
  }

  // One track per segment: the closest fit.
  std::vector<int> owner(n, -1);
  for (int k = 0; k < m; ++k)
    if (chosen[k] >= 0 && (owner[chosen[k]] < 0 || score[k] < score[owner[chosen[k]]]))
      owner[chosen[k]] = k;

  std::vector<Track> kept;
  kept.reserve(m + n);
  for (int k = 0; k < m; ++k) {
    Track t = tracks_[k];
    const int j = chosen[k];
    if (j < 0 || owner[j] != k) {
      if (++t.missed > options_.max_missed_frames) {
        ++st.dropped;
        continue;
      }
      kept.push_back(t);
      continue;
    }
    const LineSegment& seen = current.segments[j];
    const double dt = now - t.seen_at;
    if (dt > 0.0) {
      // The line's motion: the old midpoint to its foot on the new line, and the turn.
      const Eigen::Vector3d l = line_through(seen.p1, seen.p2);
      const Eigen::Vector2d mid = t.segment.midpoint();
      const double distance = l.dot(homogeneous(mid));
      t.shift = -distance * l.head<2>() / dt;
      t.turn = wrap_angle(direction_angle(seen) - direction_angle(t.segment)) / dt;
      t.has_motion = true;
    }
    t.segment = seen;
    t.seen_at = now;
    t.missed = 0;
    if (descriptors) t.descriptor = current.descriptors.row(j).clone();
    ids[j] = t.id;
    kept.push_back(t);
    ++st.matched;
  }
  for (int j = 0; j < n; ++j) {
    if (ids[j] >= 0) continue;
    Track t;
    t.id = next_id_++;
    t.segment = current.segments[j];
    t.seen_at = now;
    if (descriptors) t.descriptor = current.descriptors.row(j).clone();
    ids[j] = t.id;
    kept.push_back(t);
    ++st.started;
  }
  tracks_ = std::move(kept);
  return ids;
}

}  // namespace hybrid_vo
