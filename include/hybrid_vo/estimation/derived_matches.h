#pragma once

#include "hybrid_vo/geometry/option_fields.h"
#include <vector>

#include "hybrid_vo/estimation/matches.h"

namespace hybrid_vo {

// Where a point-like match comes from, so that ablations can switch each source off.
enum class PointSource { kPoint, kJunction, kEndpoint };

struct DerivedPoint {
  PointMatch match;  // pixels
  PointSource source = PointSource::kPoint;
  int first = -1;    // point index, or the (first) line index
  int second = -1;   // junction: the second line; endpoint: 0 or 1 (which end of `first`)
};

struct JunctionOptions {
  // How far beyond a segment's end its intersection with the other segment may lie, in pixels:
  // tolerance_px, or more for a long segment that meets the other steeply, length_fraction of
  // its length times the sine of their angle, up to max_tolerance_px. A faint corner breaks its
  // edges off short of it (white panels on a floor: 5-15 px), and a long segment that meets
  // another at a right angle points at the corner precisely even from afar; extrapolated at a
  // shallow angle, the intersection slides along the lines.
  double tolerance_px = 3.0;
  double length_fraction = 0.0;
  double max_tolerance_px = 20.0;
  // Junctions of nearly parallel segments are badly localised along the lines.
  double min_angle_deg = 15.0;
  // A junction within this distance of an earlier one in either image joins the point pool only
  // once (distinct_junctions).
  double duplicate_px = 2.0;
};

template <typename Visit>
void visit_fields(JunctionOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(non_negative(), o.tolerance_px, o.length_fraction, o.max_tolerance_px,
                  o.min_angle_deg, o.duplicate_px);
}

// Junctions of segment matches (paper supp. Sec. B): pairs whose intersection lies on both
// segments, up to the tolerance (junction_tolerance_px), in both images. Invalid (zero-length, non-finite) segments never
// form junctions. O(n^2) in the number of segments.
std::vector<DerivedPoint> find_junctions(const std::vector<LineMatch>& lines,
                                         const JunctionOptions& options = {});

// How far past the end of a segment of `length` pixels that meets another at an angle whose sine
// is `sin_angle` a junction may lie (JunctionOptions).
double junction_tolerance_px(double length, double sin_angle, const JunctionOptions& options);

// Indices of the junctions that do not repeat an earlier one: one within `radius_px` of an earlier
// kept junction in image 1 or in image 2 is left out. One image position has one correspondence,
// so of two such junctions at most one is right. They come from a segment matched twice (split
// by the detector in one image) and would count the same evidence twice: on KITTI frames 20-22
// with 40 points, five junctions of three line crossings, two of them doubled, outvoted the
// points for a pose 30 deg off. radius_px <= 0 (or NaN) keeps every junction.
std::vector<int> distinct_junctions(const std::vector<DerivedPoint>& junctions, double radius_px);

// Segment endpoints as point matches. Endpoints of matched segments correspond only when the
// detector cut both segments at the same 3D points, so they are a weaker source than junctions;
// the ends are paired so that the segments point the same way in both images.
std::vector<DerivedPoint> segment_endpoints(const std::vector<LineMatch>& lines);

// A segment with finite endpoints at least `min_length` pixels apart.
bool valid_segment(const LineSegment& s, double min_length = 1e-6);

}  // namespace hybrid_vo
