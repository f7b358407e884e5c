#pragma once

#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/features/line_detection.h"

namespace hybrid_vo {

// LBD description (Zhang & Koch, "An efficient and robust line segment matching approach based on
// LBD descriptor and pairwise geometric consistency", JVCIR 2013) of given segments, computed by
// cv::line_descriptor::BinaryDescriptor.
struct LineDescriptionOptions {
  // Descriptors per segment, on a Gaussian pyramid with factor 2 (scales 1, 1/2, 1/4, ...). The
  // distance between two segments is the smallest over all pairs of their octaves, so the 63 px
  // high support region follows a scale change of up to 2^(octaves-1) (LBD's multi-scale
  // matching). The second octave adds ~50 % to the description time, the third ~15 %.
  int octaves = 3;
  // Describe from this pyramid level on (0: full resolution). Level 1 roughly halves the
  // description time; the video preset uses it on KITTI's 1241 px wide frames.
  int first_octave = 0;
  int band_width = 7;          // LBD: 9 bands of this many pixels across the line
  double min_length_px = 8.0;  // shorter given segments get no descriptor
  // LBD's 72 floats per octave, compared by L2, rather than its 256-bit binary form (Hamming):
  // the binary form keeps only comparisons between bands. On the homography pairs of the
  // line-matching benchmark (Li et al. 2016, ED segments, two octaves) the plain nearest
  // neighbour was a ground-truth match for 56 % of the groups with bits, 73 % with floats.
  bool float_descriptor = true;
  // false: the segments are oriented by their gradient but get no descriptor.
  bool describe = true;
};

struct LineMatchingOptions {
  LineDetectionOptions detection;
  LineDescriptionOptions description;
  // Anchors: mutual nearest neighbours that pass the ratio test and the distance cap.
  double ratio = 0.8;  // ratio test on LBD distances; >= 1 disables
  bool mutual = true;
  int max_hamming = 80;  // cap on the binary LBD distance (of 256 bits)
  double max_l2 = 0.35;  // cap on the float LBD distance (unit vectors, so at most 2)
  // The geometric filter drops matches that disagree with the geometric change between the
  // images, and admits `candidates` (each image-1 segment's nearest neighbours, whatever their
  // ratio or mutuality) when their neighbourhood vouches for them:
  // 1. global: the rotation between matched segment directions must lie within
  //    max_rotation_deviation_deg of the dominant one (histogram vote over the anchors);
  // 2. local: the voters are the anchors supported by >= min_support other anchors. A voter
  //    supports a match when it is among the match's `neighbours` nearest voters in image 1 and
  //    its partner among the partner's nearest in image 2, it rotates alike (within
  //    max_local_rotation_deg) and lies on the same side of the match in both images;
  // 3. position: the affine map fitted to a match's supporters must put the image-1 segment on
  //    its partner's line (within max_position_error_px, more where the neighbourhood is not
  //    affine) and overlapping it. A voter then needs min_support supporters, a candidate
  //    min_candidate_support.
  bool geometric_filter = true;
  double max_rotation_deviation_deg = 45.0;
  int candidates = 2;
  int neighbours = 30;
  double max_local_rotation_deg = 15.0;
  int min_support = 2;
  int min_candidate_support = 3;
  double max_position_error_px = 3.0;  // <= 0 disables the position check
};

// The video preset for consecutive frames (small baseline, little scale change, a 30 ms budget
// for a KITTI pair): FLD segments of at least 30 px, with the gradient threshold adapted to low
// contrast and collinear fragments joined, one LBD octave at half resolution with 5 px bands,
// about a third of the cost of one full-resolution octave with 7 px bands.
LineMatchingOptions video_line_matching_options();

// Segments and their LBD descriptors, one row each (octaves side by side: 72 floats or 32 bytes
// per octave). Segments for which no descriptor can be computed are dropped. Each segment is
// oriented as LBD orients it: its dark side lies to the left of p1->p2 as seen on screen, i.e.
// the gradient across it (dark to bright) points along (-dy, dx) in image coordinates (x right,
// y down). Matched segments therefore run the same way in both images.
struct LineFeatures {
  std::vector<LineSegment> segments;
  cv::Mat descriptors;
};

// Detection (LSD or FLD) and description. Empty features for an empty image.
LineFeatures detect_line_features(const GrayImage& image,
                                  const LineMatchingOptions& options = {});
// Description of given segments (e.g. a benchmark's detections). `kept` (optional) receives,
// per row of the result, the index of its segment in `segments`. The returned segments may have
// their endpoints swapped (the orientation above).
LineFeatures describe_line_segments(const GrayImage& image,
                                    const std::vector<LineSegment>& segments,
                                    std::vector<int>* kept = nullptr,
                                    const LineDescriptionOptions& options = {});

// Matches between two images' segments; `pairs` receives the segment indices when given. The
// segments keep LBD's orientation (by the gradient), so matched endpoints run the same way. With
// the geometric filter, one segment may match several fragments of the same edge.
std::vector<LineMatch> match_line_features(const LineFeatures& a, const LineFeatures& b,
                                           const LineMatchingOptions& options = {},
                                           std::vector<std::pair<int, int>>* pairs = nullptr);

// The LBD distance between row `i` of `a` and row `j` of `b` (descriptors as in LineFeatures), on
// the scale match_line_features uses: Hamming bits, or 128 x L2 for floats, the smallest over
// all pairs of octaves. Infinity for mismatched descriptors.
float line_descriptor_distance(const cv::Mat& a, int i, const cv::Mat& b, int j);
// The largest LBD distance match_line_features accepts (max_hamming or 128 x max_l2).
double max_line_descriptor_distance(const LineMatchingOptions& options, const cv::Mat& descriptors);

}  // namespace hybrid_vo
