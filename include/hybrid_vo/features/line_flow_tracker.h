#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hybrid_vo/features/line_tracker.h"
#include "hybrid_vo/features/point_flow_field.h"
#include "hybrid_vo/features/segment_flow.h"
#include "hybrid_vo/features/segment_motion.h"

namespace hybrid_vo {

// Segment tracks that live on the images' flow (issue 57): each frame moves every track by the
// flow of points sampled along it (segment_flow.h), predicted by the camera's rotation and the
// track's own last motion, as LineTracker predicts; the detector runs only where the tracks
// thin out, and its segments refresh the tracks they continue (their ends, which the flow
// measures only by the prediction) and start the rest. Detecting and describing every frame cost
// 11-13 ms of a 640x480 frame (doc/performance.md).
struct LineFlowTrackerOptions {
  SegmentFlowOptions flow;
  // A track is predicted by the tracked points within point_radius_px of it (at least
  // min_points; point_flow_field.h) and looked for up to min_reach_px plus spread_factor times
  // their motions' spread across it around that. Without such points, by the camera's rotation
  // and its own velocity: up to min_reach_px plus motion_fraction of the motion its velocity
  // predicts (constant velocity is a guess), and young_reach_px for a track seen once, which has
  // no velocity yet (LineTracker's tolerances); never farther than that. A wider search than
  // the prediction needs meets parallel edges of the same contrast (a panel's seams).
  double point_radius_px = 40.0;
  int min_points = 4;
  double spread_factor = 2.0;
  double min_reach_px = 4.0;
  double motion_fraction = 0.5;
  double young_reach_px = 12.0;
  // The segments are detected again once the tracks fall below redetect_below of what the last
  // detection left, or max_frames_between_detections frames after it, or (with stamps) the
  // next frame would come max_seconds_between_detections after it: new structure comes into
  // view and the ends drift with the motion, which goes by time, not frames (the textured
  // corridor at 10 Hz ended 0.073 -> 0.119 degrees off when detecting every fourth frame).
  double redetect_below = 0.8;
  int max_frames_between_detections = 4;
  double max_seconds_between_detections = 0.2;
  // A detected segment continues a track when its direction (oriented by the gradient) lies
  // within associate_angle_deg of the track's, its line within associate_offset_px of the
  // track's over their overlap, and that overlap spans associate_overlap of the shorter one.
  // A segment that overlaps a track it does not continue starts none (one edge, one track).
  double associate_angle_deg = 3.0;
  double associate_offset_px = 2.0;
  double associate_overlap = 0.5;
};

template <typename Visit>
void visit_fields(LineFlowTrackerOptions& o, Visit&& visit) {
  visit_fields(o.flow, prefixed("flow_", visit));
  HYBRID_VO_FIELDS(fraction(), o.redetect_below, o.associate_overlap);
  HYBRID_VO_FIELDS(positive(), o.max_seconds_between_detections);
  HYBRID_VO_FIELDS(non_negative(), o.min_reach_px, o.motion_fraction, o.young_reach_px,
                  o.point_radius_px, o.min_points, o.spread_factor);
  HYBRID_VO_FIELDS(positive(), o.max_frames_between_detections, o.associate_angle_deg,
                  o.associate_offset_px);
}

class LineFlowTracker {
 public:
  static constexpr double kNoStamp = std::numeric_limits<double>::quiet_NaN();
  explicit LineFlowTracker(const LineFlowTrackerOptions& options = {});

  // Moves the tracks from the last frame's image into this one's (pyramid_images of the
  // frame's pyramid); tracks the flow loses end. `stamp` and `image_motion` as LineTracker::track
  // takes them; `points`, optional, the motion of the tracked points into this frame. The tracks
  // are independent: `parallel` may spread them over threads, with the same result. An image of
  // another size starts afresh.
  void track(const std::vector<cv::Mat>& pyramid, double stamp,
             const Eigen::Matrix3d& image_motion = Eigen::Matrix3d::Identity(),
             const PointFlowField* points = nullptr, const ParallelFor& parallel = {},
             LineTrackingStats* stats = nullptr);
  // Whether the next frame's segments should be detected (before its track, so that the
  // detector may run beside the points' tracking): see redetect_below.
  bool wants_detection() const;
  // This frame's detected segments (oriented by the gradient, as describe_line_segments gives
  // them): each refreshes the track it continues or starts one; a track that several continue
  // takes the one it overlaps most, and tracks continued by the same segment become one (the
  // oldest). Adds to `stats`.
  void add_detections(const std::vector<LineSegment>& detected, LineTrackingStats* stats = nullptr);
  // The tracks in this frame: their segments (oriented) and ids, in the same order.
  std::vector<LineSegment> segments() const;
  std::vector<int64_t> ids() const;
  int num_tracks() const { return static_cast<int>(tracks_.size()); }
  void reset();

 private:
  struct Track {
    int64_t id = 0;
    LineSegment segment;
    double seen_at = 0.0;
    SegmentMotion motion;
  };
  Track new_track(const LineSegment& segment);

  LineFlowTrackerOptions options_;
  std::vector<Track> tracks_;
  std::vector<cv::Mat> previous_;  // the last frame's pyramid images
  int64_t next_id_ = 0;
  double now_ = 0.0;  // stamps, or one unit per frame without them
  bool started_ = false;
  int frames_since_detection_ = 0;
  double detected_at_ = 0.0;  // the clock at the last detection
  double last_step_ = 0.0;    // the clock's last step between frames
  int tracks_after_detection_ = 0;
};

}  // namespace hybrid_vo
