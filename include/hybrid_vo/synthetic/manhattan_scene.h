#pragma once

#include <array>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {

struct ManhattanSceneOptions {
  int num_points = 500;                // point matches, including outliers
  double planar_point_fraction = 0.5;  // fraction of inlier points lying on the scene's planes
  int num_segments = 150;              // segment matches, including wrong ones
  double noise_px = 0.5;               // Gaussian noise on every pixel coordinate
  double point_outlier_ratio = 0.0;    // fraction of point matches whose x2 is a random pixel
  double line_outlier_ratio = 0.0;     // fraction of segment matches paired with a wrong segment
  int num_vps = 3;                     // VP matches provided (0..3): the first Manhattan directions
  // 0: VPs are the exact directions. k > 0: each VP is the least-squares fit of the first k inlier
  // segments of its direction in each image (the exact direction when fewer than 2 exist).
  int lines_per_vp_fit = 0;
  // Angular noise of each provided VP, per camera: a rotation by exactly this angle about a random
  // axis orthogonal to the direction, applied after the fit.
  double vp_noise_deg = 0.0;
  bool orient_vps = false;  // d2 = +R d1 and sign_known; else each sign random and unknown
  double focal_px = 600.0;
  int width = 800, height = 600;
  double baseline = 0.5;           // metres between the camera centres (0: pure rotation)
  double max_rotation_deg = 20.0;  // rotation angle of camera 2, uniform in [0, max]
  double junction_fraction = 0.3;  // fraction of inlier segments generated as junction pairs
  double min_segment_px = 40.0;    // segment length in image 1
  double max_segment_px = 300.0;
};

template <typename Visit>
void visit_fields(ManhattanSceneOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(non_negative(), o.num_points, o.num_segments, o.noise_px, o.num_vps,
                  o.lines_per_vp_fit, o.vp_noise_deg, o.baseline, o.max_rotation_deg);
  HYBRID_VO_FIELDS(fraction(), o.planar_point_fraction, o.point_outlier_ratio, o.line_outlier_ratio,
                  o.junction_fraction);
  HYBRID_VO_FIELDS(any_value(), o.orient_vps);
  HYBRID_VO_FIELDS(positive(), o.focal_px, o.width, o.height, o.min_segment_px, o.max_segment_px);
}

// An axis-aligned plane of the scene: normal . X = offset in camera-1 coordinates, with
// normal = directions.col(direction). The box faces are finite; only this equation is exposed.
struct ManhattanPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  int direction = 0;
};

enum class JunctionType {
  kL,  // both segments end at the junction
  kT,  // the first segment crosses it, the second ends there
  kX,  // both cross it
};

// Two inlier segments generated to meet on a plane, in the same place in both images.
struct ManhattanJunction {
  std::array<int, 2> segments = {-1, -1};  // indices into matches.lines
  JunctionType type = JunctionType::kX;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // camera-1 coordinates
};

struct ManhattanScene {
  PinholeCamera camera1, camera2;
  RelativePose truth;       // unit t (zero when the baseline is 0)
  double baseline_m = 0.0;  // |t| before normalisation
  // Columns: the Manhattan directions in camera-1 coordinates; 0 is roughly vertical (pointing
  // down), 1 roughly along camera 1's optical axis, 2 roughly along its x axis. A rotation.
  Eigen::Matrix3d directions = Eigen::Matrix3d::Identity();
  std::vector<ManhattanPlane> planes;
  // Points, segments, VPs (vps[k] is direction k) and line_vp (the segment's direction when its
  // VP is provided, else -1; wrong matches keep the label of their image-1 segment).
  TwoViewMatches matches;
  std::vector<bool> point_inlier, line_inlier;
  std::vector<int> point_plane;           // plane index or -1 (free volume)
  std::vector<int> line_plane;            // plane of the image-1 segment
  std::vector<int> line_direction;        // 0..2: the image-1 segment's Manhattan direction
  std::vector<Eigen::Vector3d> points3d;  // camera 1; outliers: the point behind x1
  // Camera-1 coordinates of the endpoints behind s1.p1 and s1.p2 (inliers: also s2.p1, s2.p2).
  std::vector<std::array<Eigen::Vector3d, 2>> segments3d;
  std::vector<ManhattanJunction> junctions;
};

// A random two-view frame of a box-shaped Manhattan scene (street canyon, corridor or room) seen
// from inside: ground, two side walls, a back wall 8-15 m ahead and sometimes a ceiling. Every
// inlier point and segment endpoint lies in both images with depth >= 1.5 m in both cameras.
// Deterministic for a given rng state. Throws std::invalid_argument for invalid options and
// std::runtime_error when no scene fits them after bounded redraws (e.g. a baseline that leaves
// the box, or segments longer than the image).
ManhattanScene generate_manhattan_scene(std::mt19937_64& rng,
                                        const ManhattanSceneOptions& options = {});

}  // namespace hybrid_vo
