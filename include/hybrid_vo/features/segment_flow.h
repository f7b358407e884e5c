#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/features/worker_thread.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/option_fields.h"

namespace hybrid_vo {

// A segment followed from one frame into the next by the flow of points sampled along it
// (issue 57, as PL-VINS's front end does): each sample's intensity profile across the edge is
// searched for along the predicted segment's normal, coarse to fine over the image pyramid, and
// the line is fitted again to the samples that agree. Only the motion across the edge is
// measured (along it an edge looks the same everywhere); the ends are found along the fitted line,
// where the edge stops.
struct SegmentFlowOptions {
  // Samples about sample_spacing_px apart, at least min_samples and at most max_samples, the
  // outer ones end_inset_px inside the ends: near a corner the other edge bends a sample's
  // profile, and a few tenths of a pixel at one end tilt a short segment by tenths of a degree
  // (TartanAir's pairs 0.068 -> 0.061 degrees at 6 px instead of 3).
  double sample_spacing_px = 8.0;
  int min_samples = 6;
  int max_samples = 24;
  double end_inset_px = 6.0;
  // The profile: 2 * profile_half_px + 1 values a pixel apart across the edge (2 to 30).
  int profile_half_px = 4;
  // The search: at most +- search_px pixels (at most 40) of the level it starts at, the finest
  // of `levels` above full resolution whose pixels cover the segment's reach, then +- 2 at each
  // finer one; at full resolution to a fraction of a pixel.
  int search_px = 6;
  int levels = 2;
  // The coarse search is the segment's: the offset (and its change along the segment, up to
  // coarse_turn_deg) on which the samples' profile correlations agree best; it fails where
  // another peak 2 px or more away is nearly as good (a parallel edge of the same contrast): its
  // decorrelation (1 - mean correlation) at most rival_ratio times the best's plus
  // rival_margin. A shifted step still correlates 0.9 with itself, so the correlations alone
  // cannot be compared by a ratio. Each sample is then found from there where its correlation
  // reaches min_correlation.
  double coarse_turn_deg = 3.0;
  double min_correlation = 0.8;
  double rival_ratio = 3.0;
  double rival_margin = 0.02;
  // ... and its contrast (the profile's spread) differs from the followed one's by at most this
  // factor either way (the correlation alone takes a faint edge for a strong one).
  double max_contrast_ratio = 2.0;
  // The line: fitted to the found samples, those farther than max_residual_px, or than three
  // robust sigmas of their distances (median based) but at least min_residual_px, dropped; it holds
  // when at least min_inliers and min_inlier_share of the samples inside the image remain and
  // its direction is within max_turn_deg of the prediction's.
  double max_residual_px = 1.0;
  double min_residual_px = 0.3;
  int min_inliers = 4;
  double min_inlier_share = 0.6;
  double max_turn_deg = 10.0;
  // The ends are looked for up to this far beyond the predicted ones (0: within them; a segment
  // grows when the detector sees more of it). Beyond, segments met others in junctions that did
  // not serve: KITTI 06's 1 s windows 0.067 -> 0.082 degrees at 8 px, 0.071 at 0 (seeds 0-4),
  // TartanAir's 0.105 -> 0.147 at 4 px, 0.114 at 0.
  double end_search_px = 0.0;
  // Shorter segments are lost (they carry little direction).
  double min_length_px = 30.0;
};

template <typename Visit>
void visit_fields(SegmentFlowOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(at_least(1), o.max_contrast_ratio);
  HYBRID_VO_FIELDS(positive(), o.sample_spacing_px, o.min_samples, o.max_samples,
                  o.min_inliers, o.max_residual_px, o.max_turn_deg);
  // As track_segments_by_flow takes them (it tracks nothing beyond).
  HYBRID_VO_FIELDS(between(2, 30), o.profile_half_px);
  HYBRID_VO_FIELDS(between(1, 40), o.search_px);
  HYBRID_VO_FIELDS(non_negative(), o.end_inset_px, o.levels, o.min_length_px, o.min_residual_px,
                  o.end_search_px);
  HYBRID_VO_FIELDS(fraction(), o.min_correlation, o.rival_margin, o.min_inlier_share);
  HYBRID_VO_FIELDS(non_negative(), o.rival_ratio, o.coarse_turn_deg);
}

// Where one segment went.
struct SegmentFlow {
  bool found = false;
  LineSegment segment;  // in the next image, p1 and p2 as in the given segment
  int samples = 0;      // samples whose search lay inside the image
  int inliers = 0;      // of those, on the fitted line
  double rms_px = 0.0;  // the inliers' distance to it
};

// The 8-bit levels of an image pyramid (level 0 full resolution, each next one pyrDown's half),
// such as cv::buildOpticalFlowPyramid gives with or without derivatives: the derivative levels
// are left out.
std::vector<cv::Mat> pyramid_images(const std::vector<cv::Mat>& pyramid);

// The flow of `segments` from the image of pyramid `from` into that of `to` (pyramid_images of
// both: same size and levels), each searched for around its `predicted` place (one per
// segment; the segment itself when empty) up to its `reach_px` across it (how far off the
// prediction may be; when empty, search_px at the coarsest level). The segments are
// independent: `parallel` may spread them over threads, with the same result.
std::vector<SegmentFlow> track_segments_by_flow(const std::vector<cv::Mat>& from,
                                                const std::vector<cv::Mat>& to,
                                                const std::vector<LineSegment>& segments,
                                                const std::vector<LineSegment>& predicted,
                                                const std::vector<double>& reach_px = {},
                                                const SegmentFlowOptions& options = {},
                                                const ParallelFor& parallel = {});

}  // namespace hybrid_vo
