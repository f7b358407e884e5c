#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/option_fields.h"

namespace hybrid_vo {

struct VpDetectionOptions {
  // A segment (a segment match: in both images) supports a VP when its orthogonal distance
  // (Tardif 2009) is below this, in pixels.
  double inlier_threshold_px = 2.0;
  double min_segment_length_px = 15.0;  // shorter segments say little about their direction
  int max_vps = 4;
  int min_inliers = 6;                  // supporting segments (matches) of a VP
  // Or fewer, but long: a VP's evidence is how much of the image its segments span, not their
  // number (a white room has a handful of long edges). A VP with at least min_long_inliers
  // segments whose lengths sum to min_support_px per image is kept too; 0 disables.
  int min_long_inliers = 0;
  double min_support_px = 0.0;
  int max_iterations = 1000;            // RANSAC draws per VP; fewer when the support is clear
  double confidence = 0.999;
  double merge_angle_deg = 2.0;         // near-duplicate VPs (in every image) are merged
  bool refine = true;                   // Levenberg-Marquardt (Ceres) on the inliers' distances
  // Manhattan prior: keep only VPs within this tolerance of orthogonal to the VPs already found.
  bool manhattan = false;
  double manhattan_tolerance_deg = 5.0;
  // A VP match's sign counts as known when this fraction of its segments point the same way
  // relative to it in both images (matched segments keep their orientation, e.g. LBD).
  double sign_agreement = 0.9;
  uint64_t seed = 0;
};

template <typename Visit>
void visit_fields(VpDetectionOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(positive(), o.inlier_threshold_px);
  HYBRID_VO_FIELDS(non_negative(), o.min_segment_length_px, o.max_vps, o.min_long_inliers,
                  o.min_support_px, o.max_iterations, o.merge_angle_deg,
                  o.manhattan_tolerance_deg);
  HYBRID_VO_FIELDS(at_least(2), o.min_inliers);  // two segments make a VP
  HYBRID_VO_FIELDS(open_fraction(), o.confidence);
  HYBRID_VO_FIELDS(any_value(), o.refine, o.manhattan, o.seed);
  HYBRID_VO_FIELDS(fraction(), o.sign_agreement);
}

// A VP in one image: a unit direction in the camera frame (K^-1 v), its supporting segments, and
// its score (the summed length of the supporting segments in pixels).
struct ImageVp {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  std::vector<int> inliers;
  double score = 0.0;
};

struct SingleImageVps {
  std::vector<ImageVp> vps;  // strongest first
  std::vector<int> labels;   // per segment: VP index or -1
};

// VP matches between two images and the labels of the segment matches.
struct MatchedVps {
  std::vector<VpMatch> matches;            // directions in each camera, strongest first
  std::vector<int> labels;                 // per line match: index into `matches` or -1
  std::vector<std::vector<int>> inliers;   // per VP match: its line matches
  std::vector<double> scores;              // per VP match: summed segment length, both images
};

// Single-image detection: sequential RANSAC over segments with a 2-segment minimal sample
// (v = l1 x l2), merging, reassignment and refinement.
SingleImageVps detect_vanishing_points(const PinholeCamera& camera,
                                       const std::vector<LineSegment>& segments,
                                       const VpDetectionOptions& options = {});

// Joint detection and matching (paper Sec. 3): the same fitting over segment matches, with a
// sample of two matches giving v = l1 x l2 in each image and inliers required in both images.
MatchedVps detect_vanishing_points_joint(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                         const std::vector<LineMatch>& lines,
                                         const VpDetectionOptions& options = {});

// The baseline ("standard"): detect in each image separately, then match VPs by how many line
// matches connect them.
MatchedVps detect_vanishing_points_standard(const PinholeCamera& camera1,
                                            const PinholeCamera& camera2,
                                            const std::vector<LineMatch>& lines,
                                            const VpDetectionOptions& options = {});

}  // namespace hybrid_vo
