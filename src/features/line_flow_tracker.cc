#include "hybrid_vo/features/line_flow_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hybrid_vo {
namespace {

// How far detected segment `d` lies from track segment `t` that it continues (the mean distance
// of its line to t's ends of their overlap, px), or -1 when it does not continue it
// (LineFlowTrackerOptions' association).
double continuation(const LineSegment& t, const LineSegment& d, double cos_angle, double offset,
                    double min_overlap) {
  const double lt = t.length(), ld = d.length();
  if (!(lt > 0.0) || !(ld > 0.0)) return -1.0;
  const Eigen::Vector2d ut = (t.p2 - t.p1) / lt, ud = (d.p2 - d.p1) / ld;
  if (ut.dot(ud) < cos_angle) return -1.0;
  const double a = ut.dot(d.p1 - t.p1), b = ut.dot(d.p2 - t.p1);
  const double lo = std::max(0.0, std::min(a, b)), hi = std::min(lt, std::max(a, b));
  if (hi - lo < min_overlap * std::min(lt, ld)) return -1.0;
  const Eigen::Vector3d line = line_through(d.p1, d.p2);
  const double e1 = std::abs(line.dot(homogeneous(t.p1 + lo * ut)));
  const double e2 = std::abs(line.dot(homogeneous(t.p1 + hi * ut)));
  if (!(e1 <= offset) || !(e2 <= offset)) return -1.0;
  return 0.5 * (e1 + e2);
}

// Segment `t` along its own line, extended to cover `d`'s ends projected onto it.
LineSegment spanning(const LineSegment& t, const LineSegment& d) {
  const double length = t.length();
  if (!(length > 0.0)) return t;
  const Eigen::Vector2d u = (t.p2 - t.p1) / length;
  const double lo = std::min({0.0, u.dot(d.p1 - t.p1), u.dot(d.p2 - t.p1)});
  const double hi = std::max({length, u.dot(d.p1 - t.p1), u.dot(d.p2 - t.p1)});
  return LineSegment(t.p1 + lo * u, t.p1 + hi * u);
}

}  // namespace

LineFlowTracker::LineFlowTracker(const LineFlowTrackerOptions& options) : options_(options) {}

void LineFlowTracker::reset() {
  tracks_.clear();
  previous_.clear();
  started_ = false;
  now_ = 0.0;
  frames_since_detection_ = 0;
  detected_at_ = last_step_ = 0.0;
  tracks_after_detection_ = 0;
}

LineFlowTracker::Track LineFlowTracker::new_track(const LineSegment& segment) {
  Track t;
  t.id = next_id_++;
  t.segment = segment;
  t.seen_at = now_;
  return t;
}

void LineFlowTracker::track(const std::vector<cv::Mat>& pyramid, double stamp,
                            const Eigen::Matrix3d& image_motion, const PointFlowField* points,
                            const ParallelFor& parallel, LineTrackingStats* stats) {
  LineTrackingStats local;
  LineTrackingStats& st = stats ? *stats : local;
  st = LineTrackingStats();
  const double now = std::isfinite(stamp) ? stamp : (started_ ? now_ + 1.0 : 0.0);
  if ((started_ && now < now_) || pyramid.empty() ||
      (!previous_.empty() && previous_[0].size() != pyramid[0].size()))
    reset();
  last_step_ = started_ && std::isfinite(stamp) ? now - now_ : 0.0;
  started_ = true;
  now_ = now;
  ++frames_since_detection_;
  st.tracks = static_cast<int>(tracks_.size());
  if (!previous_.empty() && !tracks_.empty()) {
    const bool usable = all_finite(image_motion) && std::abs(image_motion.determinant()) > 1e-12;
    const Eigen::Matrix3d H = usable ? image_motion : Eigen::Matrix3d::Identity();
    std::vector<LineSegment> segments, predicted, carried;
    std::vector<double> reach;
    for (const Track& t : tracks_) {
      segments.push_back(t.segment);
      LineSegment c;
      carried.push_back(transfer_segment(H, t.segment, &c) ? c : t.segment);
      // By the points around it where there are some, within their spread; else by the
      // rotation and the track's own velocity, whose guess is uncertain by a fraction of it
      // (the rotation's is not).
      LineSegment by_points;
      double spread = 0.0;
      if (points && points->predict(t.segment, options_.point_radius_px, options_.min_points,
                                    &by_points, &spread)) {
        predicted.push_back(by_points);
        reach.push_back(std::min(options_.young_reach_px,
                                 options_.min_reach_px + options_.spread_factor * spread));
        continue;
      }
      predicted.push_back(predict_segment(t.segment, t.motion, now - t.seen_at, H));
      const double motion = std::max((predicted.back().p1 - carried.back().p1).norm(),
                                     (predicted.back().p2 - carried.back().p2).norm());
      reach.push_back(t.motion.known ? options_.min_reach_px + options_.motion_fraction * motion
                                     : options_.young_reach_px);
    }
    const std::vector<SegmentFlow> flows = track_segments_by_flow(
        previous_, pyramid, segments, predicted, reach, options_.flow, parallel);
    std::vector<Track> kept;
    for (size_t k = 0; k < tracks_.size(); ++k) {
      if (!flows[k].found) {
        ++st.dropped;
        continue;
      }
      Track t = tracks_[k];
      const double dt = now - t.seen_at;
      // The motion beyond the rotation's: from the carried segment to the one found.
      if (dt > 0.0) t.motion = segment_motion_between(carried[k], flows[k].segment, dt);
      t.segment = flows[k].segment;
      t.seen_at = now;
      kept.push_back(t);
      ++st.matched;
    }
    tracks_ = std::move(kept);
  }
  previous_ = pyramid;
}

bool LineFlowTracker::wants_detection() const {
  return tracks_.empty() ||
         frames_since_detection_ + 1 >= options_.max_frames_between_detections ||
         (last_step_ > 0.0 &&
          now_ + last_step_ - detected_at_ > options_.max_seconds_between_detections + 1e-9) ||
         static_cast<double>(tracks_.size()) <
             options_.redetect_below * static_cast<double>(tracks_after_detection_);
}

void LineFlowTracker::add_detections(const std::vector<LineSegment>& detected,
                                     LineTrackingStats* stats) {
  LineTrackingStats local;
  LineTrackingStats& st = stats ? *stats : local;
  const int m = static_cast<int>(tracks_.size()), n = static_cast<int>(detected.size());
  const double cos_angle = std::cos(options_.associate_angle_deg * M_PI / 180.0);
  // Each track's detection: the nearest of those continuing it (of two parallel edges a pixel or
  // two apart, the one the flow followed).
  std::vector<int> choice(m, -1);
  std::vector<char> continues(n, 0);
  for (int k = 0; k < m; ++k) {
    double best = std::numeric_limits<double>::infinity();
    for (int j = 0; j < n; ++j) {
      const double offset =
          continuation(tracks_[k].segment, detected[j], cos_angle, options_.associate_offset_px,
                       options_.associate_overlap);
      if (offset < 0.0) continue;
      continues[j] = 1;
      if (offset < best) {
        best = offset;
        choice[k] = j;
      }
    }
  }
  // One track per detection: the oldest (tracks are kept in the order they started); the others
  // it continues were the same edge.
  std::vector<int> owner(n, -1);
  std::vector<Track> kept;
  for (int k = 0; k < m; ++k) {
    const int j = choice[k];
    if (j >= 0 && owner[j] >= 0) {
      ++st.dropped;
      continue;
    }
    // The track keeps its line: the detector's line of the same edge lies a few tenths of a
    // pixel off the one the flow measures (their junctions' epipolar error half as large again
    // on TartanAir's panels when a pair mixed the two); its ends reach the detection's.
    Track t = tracks_[k];
    if (j >= 0) {
      owner[j] = k;
      t.segment = spanning(t.segment, detected[j]);
    }
    kept.push_back(t);
  }
  // New tracks start on the edge as the flow measures it, for the same reason.
  std::vector<LineSegment> fresh;
  for (int j = 0; j < n; ++j)
    if (!continues[j]) fresh.push_back(detected[j]);
  const std::vector<SegmentFlow> measured =
      previous_.empty() ? std::vector<SegmentFlow>(fresh.size())
                        : track_segments_by_flow(previous_, previous_, fresh, fresh,
                                                 std::vector<double>(fresh.size(), 2.0),
                                                 options_.flow);
  for (size_t k = 0; k < fresh.size(); ++k) {
    kept.push_back(new_track(measured[k].found ? measured[k].segment : fresh[k]));
    ++st.started;
  }
  tracks_ = std::move(kept);
  frames_since_detection_ = 0;
  detected_at_ = now_;
  tracks_after_detection_ = static_cast<int>(tracks_.size());
}

std::vector<LineSegment> LineFlowTracker::segments() const {
  std::vector<LineSegment> segments;
  for (const Track& t : tracks_) segments.push_back(t.segment);
  return segments;
}

std::vector<int64_t> LineFlowTracker::ids() const {
  std::vector<int64_t> ids;
  for (const Track& t : tracks_) ids.push_back(t.id);
  return ids;
}

}  // namespace hybrid_vo
