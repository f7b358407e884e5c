#include "hybrid_vo/features/line_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "hybrid_vo/features/segment_motion.h"

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

// The segments of `segments` near `predicted` (near_prediction), in order.
void find_candidates(const LineSegment& predicted, const std::vector<LineSegment>& segments,
                     double tolerance, double cos_angle, double min_overlap,
                     std::vector<Candidate>* candidates) {
  candidates->clear();
  for (int j = 0; j < static_cast<int>(segments.size()); ++j) {
    Candidate c;
    c.j = j;
    if (near_prediction(predicted, segments[j], tolerance, cos_angle, min_overlap, &c.offset))
      candidates->push_back(c);
  }
}

// Of a track's ambiguous candidates, the nearest to its descriptor (row 0 of `descriptor`) by
// LBD distance, when below the cap and below `ratio` times the second; -1 otherwise.
int pick_by_descriptor(const cv::Mat& descriptor, const cv::Mat& descriptors,
                       const std::vector<Candidate>& candidates,
                       const LineTrackerOptions& options) {
  float d_best = std::numeric_limits<float>::infinity();
  float d_second = d_best;
  int pick = -1;
  for (const Candidate& c : candidates) {
    const float d = line_descriptor_distance(descriptor, 0, descriptors, c.j);
    if (d < d_best) {
      d_second = d_best;
      d_best = d;
      pick = c.j;
    } else if (d < d_second) {
      d_second = d;
    }
  }
  if (pick < 0 || !(d_best <= options.max_lbd_distance) ||
      (std::isfinite(d_second) && d_best >= options.ratio * d_second))
    return -1;
  return pick;
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

LineTracker::LineTracker(const LineTrackerOptions& options, const LineMatchingOptions& matching)
    : options_(options), matching_(matching) {}

void LineTracker::reset() {
  tracks_.clear();
  started_ = false;
  now_ = 0.0;
}

std::vector<int64_t> LineTracker::track(const LineFeatures& current, double stamp,
                                        LineTrackingStats* stats,
                                        const Eigen::Matrix3d& image_motion) {
  LineTrackingStats local;
  LineTrackingStats& st = stats ? *stats : local;
  st = LineTrackingStats();
  // The clock: stamps when given; time going backwards starts afresh.
  const double now = std::isfinite(stamp) ? stamp : (started_ ? now_ + 1.0 : 0.0);
  if (started_ && now < now_) reset();
  started_ = true;
  now_ = now;
  st.tracks = static_cast<int>(tracks_.size());
  const bool usable = all_finite(image_motion) && std::abs(image_motion.determinant()) > 1e-12;
  const Eigen::Matrix3d H = usable ? image_motion : Eigen::Matrix3d::Identity();
  const int n = static_cast<int>(current.segments.size());
  const bool descriptors = current.descriptors.rows == n && n > 0;
  Search s = search(current, now, H, descriptors, &st);
  if (options_.reidentify && descriptors) reidentify(current, &s, &st);
  return update_tracks(current, now, descriptors, s, &st);
}

LineTracker::Search LineTracker::search(const LineFeatures& current, double now,
                                        const Eigen::Matrix3d& H, bool descriptors,
                                        LineTrackingStats* st) const {
  const int n = static_cast<int>(current.segments.size());
  const int m = static_cast<int>(tracks_.size());
  Search s;
  s.chosen.assign(m, -1);
  std::vector<double> score(m, std::numeric_limits<double>::infinity());
  std::vector<Candidate> candidates;
  s.predictions.resize(m);
  s.carried.resize(m);
  for (int k = 0; k < m; ++k) {
    const Track& t = tracks_[k];
    if (!transfer_segment(H, t.segment, &s.carried[k])) s.carried[k] = t.segment;
    const LineSegment& predicted = s.predictions[k] =
        predict_segment(t.segment, t.motion, now - t.seen_at, H);
    // The own motion's guess is uncertain by a fraction of it; the rotation's is not.
    const double motion = std::max((predicted.p1 - s.carried[k].p1).norm(),
                                   (predicted.p2 - s.carried[k].p2).norm());
    const double tolerance = t.motion.known
                                 ? options_.max_offset_px + options_.motion_fraction * motion
                                 : options_.max_offset_young_px;
    const double cos_angle = std::cos(
        (t.motion.known ? options_.max_angle_deg : options_.young_angle_deg) * M_PI / 180.0);
    find_candidates(predicted, current.segments, tolerance, cos_angle, options_.min_overlap,
                    &candidates);
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
      pick = pick_by_descriptor(t.descriptor, current.descriptors, candidates, options_);
      if (pick < 0) continue;
      ++st->ambiguous;
    }
    s.chosen[k] = pick;
    score[k] = std::find_if(candidates.begin(), candidates.end(),
                            [pick](const Candidate& c) { return c.j == pick; })
                   ->offset;
  }

  // One track per segment: the closest fit.
  s.owner.assign(n, -1);
  for (int k = 0; k < m; ++k)
    if (s.chosen[k] >= 0 && (s.owner[s.chosen[k]] < 0 || score[k] < score[s.owner[s.chosen[k]]]))
      s.owner[s.chosen[k]] = k;
  for (int k = 0; k < m; ++k)
    if (s.chosen[k] >= 0 && s.owner[s.chosen[k]] != k) s.chosen[k] = -1;
  return s;
}

void LineTracker::reidentify(const LineFeatures& current, Search* s,
                             LineTrackingStats* st) const {
  // LBD matching of every described track against the whole frame, so that its geometric filter
  // sees the context, of which only the lost tracks' pairs with free segments are taken. It runs
  // when many are lost at once (a turn starting, a jolt), not for the few a steady frame loses.
  const int m = static_cast<int>(tracks_.size());
  LineFeatures described;
  std::vector<int> track_of_row;
  int lost = 0;
  for (int k = 0; k < m; ++k) {
    const Track& t = tracks_[k];
    if (t.descriptor.cols != current.descriptors.cols ||
        t.descriptor.type() != current.descriptors.type())
      continue;
    described.segments.push_back(s->predictions[k]);
    described.descriptors.push_back(t.descriptor);
    track_of_row.push_back(k);
    lost += s->chosen[k] < 0;
  }
  if (lost < std::max<double>(options_.reidentify_min_lost,
                              options_.reidentify_min_fraction * static_cast<double>(m)))
    return;
  std::vector<std::pair<int, int>> pairs;
  match_line_features(described, current, matching_, &pairs);
  for (const auto& [row, j] : pairs) {
    const int k = track_of_row[row];
    if (s->chosen[k] >= 0 || s->owner[j] >= 0) continue;
    s->chosen[k] = j;
    s->owner[j] = k;
    ++st->reidentified;
  }
}

std::vector<int64_t> LineTracker::update_tracks(const LineFeatures& current, double now,
                                                bool descriptors, const Search& s,
                                                LineTrackingStats* st) {
  const int n = static_cast<int>(current.segments.size());
  const int m = static_cast<int>(tracks_.size());
  std::vector<int64_t> ids(n, -1);
  std::vector<Track> kept;
  kept.reserve(m + n);
  for (int k = 0; k < m; ++k) {
    Track t = tracks_[k];
    const int j = s.chosen[k];
    if (j < 0) {
      if (++t.missed > options_.max_missed_frames) {
        ++st->dropped;
        continue;
      }
      // Coasting: where it should be now, so that the next frame's rotation carries it on.
      t.segment = s.predictions[k];
      t.seen_at = now;
      kept.push_back(t);
      continue;
    }
    const LineSegment& seen = current.segments[j];
    const double dt = now - t.seen_at;
    // The motion beyond the rotation's: from the carried segment to the one seen.
    if (dt > 0.0) t.motion = segment_motion_between(s.carried[k], seen, dt);
    t.segment = seen;
    t.seen_at = now;
    t.missed = 0;
    if (descriptors) t.descriptor = current.descriptors.row(j).clone();
    ids[j] = t.id;
    kept.push_back(t);
    ++st->matched;
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
    ++st->started;
  }
  tracks_ = std::move(kept);
  return ids;
}

}  // namespace hybrid_vo
