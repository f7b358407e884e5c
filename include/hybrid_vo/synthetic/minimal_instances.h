#pragma once

#include <random>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/geometry/pose.h"
#include "hybrid_vo/solvers/minimal_solver.h"

namespace hybrid_vo {

struct MinimalInstanceOptions {
  // Standard deviation of the noise added to every image point and segment endpoint, in
  // normalised coordinates (sigma_px / f; the paper uses f = 1000).
  double noise = 0.0;
  // Segments drawn towards each VP; the VP is their least-squares intersection. The paper uses two
  // for noiseless instances and at least three for noisy ones (supp. Sec. C).
  int lines_per_vp = 2;
  // Orient every v2 as +R v1 and mark the sample's VP signs as known.
  bool orient_vps = false;
  // Lateral standard deviation of the scene around (0, 0, 5); the paper's 1 covers only +-200 px
  // of a 1000 px image at f = 1000 (one sigma). Planes and segments scale with it.
  double scene_spread = 1.0;
  // Further noisy point matches of the same scene, for local optimisation after the minimal
  // solver (the paper's supp. Fig. 5 protocol).
  int extra_points = 0;
};

template <typename Visit>
void visit_fields(MinimalInstanceOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(non_negative(), o.noise, o.extra_points);
  HYBRID_VO_FIELDS(positive(), o.lines_per_vp, o.scene_spread);
  HYBRID_VO_FIELDS(any_value(), o.orient_vps);
}

struct MinimalInstance {
  MinimalSample sample;
  RelativePose truth;  // unit t
  std::vector<Eigen::Vector2d> extra_x1, extra_x2;
};

// A random minimal problem for `id`, after the paper's generator (Sec. 5.1, supp. Sec. C):
// points ~ N((0,0,5), I), camera 2's centre ~ N(0, I). Unlike the paper, camera 2 looks towards
// the scene (random roll) and samples are redrawn until every point and endpoint lies in front of
// both cameras, so that cheirality can be checked; coplanar sets come from planes that neither
// camera sees at a grazing angle.
MinimalInstance generate_minimal_instance(SolverId id, std::mt19937_64& rng,
                                          const MinimalInstanceOptions& options = {});

}  // namespace hybrid_vo
