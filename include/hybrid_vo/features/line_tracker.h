#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "hybrid_vo/features/line_matching.h"
#include "hybrid_vo/features/segment_motion.h"

namespace hybrid_vo {

// Segment tracking in video by the segments' own geometry (issue 30): each track is predicted
// by the camera's expected rotation (an image homography, K R K^-1, from the last motion) and
// its own last image motion beyond that, searched for among the frame's detected segments near
// the prediction, and keeps a stable id, as KLT does for points. Nothing depends on point flow,
// so segments track where points cannot (white walls), and through fast turns. The LBD
// descriptor only tells apart several candidates near one prediction.
struct LineTrackerOptions {
  // A detected segment is a candidate for a track when its direction, oriented by the gradient
  // (line_matching.h, so an edge of the opposite contrast never is), lies within max_angle_deg of
  // the prediction; both predicted endpoints lie within the offset tolerance of its line; and
  // the two overlap along the line by min_overlap of the shorter. The tolerance is
  // max_offset_px plus motion_fraction of the predicted motion (constant velocity is a guess),
  // and max_offset_young_px for a track seen once, which has no motion yet.
  double max_offset_px = 3.0;
  double motion_fraction = 0.5;
  double max_offset_young_px = 12.0;
  double max_angle_deg = 4.0;
  double young_angle_deg = 8.0;  // max_angle_deg of a track seen once
  double min_overlap = 0.3;
  // Candidates of one track that are not fragments of one edge are ambiguous: the nearest by LBD
  // distance wins when it is below the matching cap and below `ratio` times the second.
  double ratio = 0.8;
  double max_lbd_distance = std::numeric_limits<double>::infinity();
  // A track not found this many frames in a row is dropped; until then it coasts on its
  // prediction, so a segment that the detector misses once keeps its id.
  int max_missed_frames = 2;
  // Re-identification: when the search loses at least reidentify_min_lost tracks and
  // reidentify_min_fraction of them (a turn starting, a jolt: the prediction is off), the lost
  // ones are matched by their LBD descriptors (match_line_features, with its geometric filter)
  // to the segments the search left over.
  bool reidentify = true;
  int reidentify_min_lost = 3;
  double reidentify_min_fraction = 0.2;
};

struct LineTrackingStats {
  int tracks = 0;     // tracks before this frame
  int matched = 0;    // found in this frame
  int ambiguous = 0;  // of those, told apart by the descriptor
  int reidentified = 0;  // of those, found by descriptor matching after the search
  int started = 0;    // new tracks from this frame's unmatched segments
  int dropped = 0;    // tracks missed for more than max_missed_frames (line flow: lost, merged)
  bool detected = false;  // the frame's segments were detected (line flow: where tracks thin out)
};

class LineTracker {
 public:
  static constexpr double kNoStamp = std::numeric_limits<double>::quiet_NaN();
  // `matching` is what the descriptors were computed with (detect_line_features) and what
  // re-identification matches by.
  explicit LineTracker(const LineTrackerOptions& options = {},
                       const LineMatchingOptions& matching = video_line_matching_options());

  // Tracks into this frame's segments (described and oriented, as detect_line_features gives
  // them; descriptors optional) and starts tracks for the unmatched ones. Returns the track id
  // of every segment of `current`, in order. `stamp` (seconds) scales the constant-velocity
  // prediction when frames are not evenly spaced. `image_motion` maps the last frame's pixels to
  // this frame's as the camera's rotation alone would (K R K^-1; identity when unknown); each
  // track's own motion is what remains beyond it. A homography that is not finite or not
  // invertible counts as identity.
  std::vector<int64_t> track(const LineFeatures& current, double stamp = kNoStamp,
                             LineTrackingStats* stats = nullptr,
                             const Eigen::Matrix3d& image_motion = Eigen::Matrix3d::Identity());
  void reset();
  // Re-identification on or off from the next frame on (a CPU budget's work level).
  void set_reidentify(bool on) { options_.reidentify = on; }
  int num_tracks() const { return static_cast<int>(tracks_.size()); }

 private:
  struct Track {
    int64_t id = 0;
    LineSegment segment;  // where it was last seen (oriented), or predicted while it coasts
    cv::Mat descriptor;   // its LBD row when last seen, or empty
    double seen_at = 0.0;  // the time of `segment`
    // Image motion per unit of time beyond the camera's rotation (segment_motion.h).
    SegmentMotion motion;
    int missed = 0;  // frames in a row without a match
  };
  // One frame's search (track's steps): per track its prediction, its segment carried by the
  // rotation alone and the segment it found (-1: none); per segment its track (-1: none).
  struct Search {
    std::vector<LineSegment> predictions, carried;
    std::vector<int> chosen;
    std::vector<int> owner;
  };
  // Each track's segment near its prediction (ambiguous ones told apart by the descriptor, when
  // `descriptors`), then one track per segment: the closest fit.
  Search search(const LineFeatures& current, double now, const Eigen::Matrix3d& H,
                bool descriptors, LineTrackingStats* st) const;
  // The tracks the search lost, re-identified by LBD among the segments it left.
  void reidentify(const LineFeatures& current, Search* s, LineTrackingStats* st) const;
  // The tracks found move on, the lost ones coast or are dropped, and the segments left start
  // tracks; returns each segment's track id.
  std::vector<int64_t> update_tracks(const LineFeatures& current, double now, bool descriptors,
                                     const Search& s, LineTrackingStats* st);

  LineTrackerOptions options_;
  LineMatchingOptions matching_;
  std::vector<Track> tracks_;
  int64_t next_id_ = 0;
  // The tracker's clock: the frames' stamps, or one unit per frame without them.
  double now_ = 0.0;
  bool started_ = false;
};

}  // namespace hybrid_vo
