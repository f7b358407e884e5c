#pragma once

// Internal: the estimator's data in the form the sampler, the scorer and the solvers need.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/derived_matches.h"
#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"

namespace hybrid_vo {

struct HybridProblem {
  PinholeCamera camera1, camera2;

  // Point-like pool: point matches, then (if enabled) junctions and endpoints.
  std::vector<Eigen::Vector2d> px1, px2;  // pixels, for Sampson errors in pixels
  std::vector<Eigen::Vector2d> n1, n2;    // normalised, for the solvers
  std::vector<DerivedPoint> origin;       // provenance of each pool entry

  // Segment matches in normalised coordinates, aligned with the input lines.
  std::vector<LineSegment> s1, s2;
  std::vector<char> line_valid;

  // VP matches as unit directions; only valid ones are kept (vp_index maps back to the input).
  std::vector<Eigen::Vector3d> d1, d2;
  std::vector<char> vp_sign_known;
  std::vector<int> vp_index;

  // All junctions, whether or not they are in the pool: line solvers build on them, and they are
  // the only way to verify a line match against a pose. `junction_lines` are the two lines.
  std::vector<Eigen::Vector2d> junction_n1, junction_n2, junction_px1, junction_px2;
  std::vector<std::pair<int, int>> junction_lines;

  // Structure for sampling: lines connected by a junction (likely coplanar, paper Sec. 2.2),
  // valid lines per VP, junctions lying on each line, pairs of orthogonal VPs.
  std::vector<std::vector<int>> line_neighbours;
  std::vector<std::vector<int>> vp_lines;        // by internal VP index
  std::vector<int> line_vp;                      // internal VP index per line, or -1
  std::vector<std::vector<int>> line_junctions;  // indices into junction_n1/n2
  std::vector<std::pair<int, int>> orthogonal_vps;  // (k, j): lines of j are orthogonal to k

  int num_pool() const { return static_cast<int>(px1.size()); }
  int num_lines() const { return static_cast<int>(s1.size()); }
  int num_vps() const { return static_cast<int>(d1.size()); }
};

}  // namespace hybrid_vo

namespace hybrid_vo {

struct HybridProblemOptions {
  bool use_vps = true;            // false: VP matches are ignored (point-only presets)
  bool use_lines = true;          // false: no line structure (no line solver, no junction points)
  bool junction_points = false;   // junctions join the point-like pool
  bool endpoint_points = false;   // segment endpoints join the point-like pool
  JunctionOptions junctions;
  double orthogonal_tolerance_deg = 10.0;
};

// Counts of input items skipped as invalid.
struct RejectedInputs {
  int points = 0, lines = 0, vps = 0;
};

// Normalises the valid matches, derives junctions and endpoints, and builds the sampling
// structure. Invalid items (non-finite, zero-length, VP labels out of range) are skipped and
// counted. `junctions` and `endpoints` receive every derived item, in pixels.
HybridProblem build_hybrid_problem(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                   const TwoViewMatches& matches,
                                   const HybridProblemOptions& options,
                                   std::vector<DerivedPoint>* junctions,
                                   std::vector<DerivedPoint>* endpoints, RejectedInputs* rejected);

}  // namespace hybrid_vo
