#pragma once

#include <utility>
#include <vector>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/frontend/line_matching.h"

namespace hybrid_vo {

// Line tracking in video: a keyframe segment is predicted into the current frame by the point
// tracks around it and searched for near that prediction; the LBD descriptor decides only between
// several candidates, and full LBD matching (match_line_features) takes the segments that the
// search loses. Consecutive video frames change little, so the geometry alone tells most matches
// apart, including those whose descriptors are too alike for the ratio test.
struct LineTrackingOptions {
  // Prediction: each endpoint moves like the median of its `neighbours` nearest point matches
  // (by their keyframe position) within `max_neighbour_distance_px`. With fewer than
  // `min_neighbours` at either endpoint the segment has no prediction.
  int neighbours = 8;
  int min_neighbours = 3;
  double max_neighbour_distance_px = 80.0;
  // Local search: a current segment is a candidate when both predicted endpoints lie within
  // max_offset_px of its line, widened by the spread of the neighbours' motions (their median
  // deviation from the median, at most max_spread_px); when its direction, oriented by the
  // gradient as LBD orients it, is within max_angle_deg of the predicted one (so an edge of the
  // opposite contrast is never a candidate); and when the two overlap along the line by at least
  // min_overlap of the shorter.
  double max_offset_px = 3.0;
  double max_spread_px = 5.0;
  double max_angle_deg = 5.0;
  double min_overlap = 0.5;
  // Several candidates that are not fragments of one edge are ambiguous: the nearest by LBD
  // distance wins when it is below the matching cap and below `ratio` times the second.
  double ratio = 0.8;
  // Segments without a prediction or a candidate are matched by full LBD matching; its matches
  // are kept for those segments only, and only with current segments the search left unmatched.
  bool descriptor_fallback = true;
};

// What happened to the keyframe's segments.
struct LineTrackingStats {
  int keyframe_segments = 0;
  int predicted = 0;  // had a prediction
  int tracked = 0;    // matched by the local search
  int ambiguous = 0;  // of those, told apart by the descriptor
  int fallback = 0;   // matched by full LBD matching
};

// Matches from `keyframe` to `current` segments (both described, as detect_line_features returns
// them) given point matches from the keyframe to the current frame in the same pixels. `pairs`
// receives the segment indices of each match. Deterministic: the order of the matches follows
// the keyframe's segments, then the fallback's.
std::vector<LineMatch> track_line_segments(const LineFeatures& keyframe,
                                           const LineFeatures& current,
                                           const std::vector<PointMatch>& point_matches,
                                           const LineMatchingOptions& matching,
                                           const LineTrackingOptions& options = {},
                                           LineTrackingStats* stats = nullptr,
                                           std::vector<std::pair<int, int>>* pairs = nullptr);

}  // namespace hybrid_vo
