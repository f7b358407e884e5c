#include "hybrid_vo/synthetic/minimal_instances.h"

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/vanishing_point.h"

namespace hybrid_vo {
namespace {

constexpr double kMinDepth = 0.5;
constexpr double kMaxImageCoordinate = 3.0;  // about a 143 degree field of view
constexpr double kMinSegmentParameter = 0.3;
constexpr double kMinPlaneViewingCosine = 0.2;

// Thrown when a draw keeps failing (say, a plane that camera 2 hardly sees): the instance is
// redrawn with new cameras instead of looping forever.
struct Redraw {};
constexpr int kMaxAttempts = 1000;

class SceneSampler {
 public:
  SceneSampler(std::mt19937_64& rng, const MinimalInstanceOptions& options)
      : rng_(rng), options_(options) {
    centre2_ = gaussian();
    const Eigen::Vector3d target = Eigen::Vector3d(0.0, 0.0, 5.0) + gaussian();
    const Eigen::Vector3d z = (target - centre2_).normalized();
    const Eigen::Vector3d r = unit();
    const Eigen::Vector3d x = (r - z * z.dot(r)).normalized();
    R_.row(0) = x.transpose();
    R_.row(1) = z.cross(x).transpose();
    R_.row(2) = z.transpose();
  }

  RelativePose truth() const { return {R_, (-R_ * centre2_).normalized()}; }

  Eigen::Vector3d point() {
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      const Eigen::Vector3d X = Eigen::Vector3d(0.0, 0.0, 5.0) + scene_offset();
      if (visible(X)) return X;
    }
    throw Redraw();
  }

  // A segment X_A -> X_A + lambda d seen by both cameras.
  void segment(const Eigen::Vector3d& d, Eigen::Vector3d* A, Eigen::Vector3d* B) {
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      *A = point();
      const double lambda = normal();
      if (std::abs(lambda) < kMinSegmentParameter) continue;
      *B = *A + options_.scene_spread * lambda * d;
      if (visible(*B)) return;
    }
    throw Redraw();
  }

  // A plane, given by a point and an orthonormal basis, that both cameras see from the front.
  void plane(Eigen::Vector3d* origin, Eigen::Vector3d* u, Eigen::Vector3d* w) {
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      *origin = Eigen::Vector3d(0.0, 0.0, 5.0) + scene_offset();
      const Eigen::Vector3d n = unit();
      // Both cameras on the same side of the (opaque) surface, neither at a grazing angle.
      const double c1 = n.dot(origin->normalized());
      const double c2 = n.dot((*origin - centre2_).normalized());
      if (c1 * c2 <= 0.0) continue;
      if (std::abs(c1) < kMinPlaneViewingCosine || std::abs(c2) < kMinPlaneViewingCosine) continue;
      *u = n.unitOrthogonal();
      *w = n.cross(*u);
      return;
    }
    throw Redraw();
  }

  Eigen::Vector3d plane_point(const Eigen::Vector3d& origin, const Eigen::Vector3d& u,
                              const Eigen::Vector3d& w) {
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      const Eigen::Vector3d X = origin + options_.scene_spread * (normal() * u + normal() * w);
      if (visible(X)) return X;
    }
    throw Redraw();
  }

  // A segment along d with X strictly inside it, seen by both cameras; false if none is found.
  bool segment_through(const Eigen::Vector3d& X, const Eigen::Vector3d& d, Eigen::Vector3d* A,
                       Eigen::Vector3d* B) {
    for (int attempt = 0; attempt < 100; ++attempt) {
      *A = X + options_.scene_spread * (std::abs(normal()) + kMinSegmentParameter) * d;
      *B = X - options_.scene_spread * (std::abs(normal()) + kMinSegmentParameter) * d;
      if (visible(*A) && visible(*B)) return true;
    }
    return false;
  }

  void add_point(const Eigen::Vector3d& X, int i, MinimalSample* s) {
    s->x1[i] = project1(X);
    s->x2[i] = project2(X);
  }

  void add_segment(const Eigen::Vector3d& A, const Eigen::Vector3d& B, int i, MinimalSample* s) {
    s->s1[i] = LineSegment(project1(A), project1(B));
    s->s2[i] = LineSegment(project2(A), project2(B));
  }

  // A VP match in direction d, from options_.lines_per_vp noisy segments.
  void add_vp(const Eigen::Vector3d& d, int i, MinimalSample* s) {
    std::vector<Eigen::Vector3d> lines1, lines2;
    for (int k = 0; k < std::max(2, options_.lines_per_vp); ++k) {
      Eigen::Vector3d A, B;
      segment(d, &A, &B);
      lines1.push_back(LineSegment(project1(A), project1(B)).line());
      lines2.push_back(LineSegment(project2(A), project2(B)).line());
    }
    s->v1[i] = vanishing_point_from_lines(lines1);
    s->v2[i] = vanishing_point_from_lines(lines2);
    if (options_.orient_vps && s->v2[i].dot(R_ * s->v1[i]) < 0.0) s->v2[i] = -s->v2[i];
  }

  Eigen::Vector3d unit() { return gaussian().normalized(); }
  Eigen::Vector3d orthogonal_unit(const Eigen::Vector3d& d) { return d.cross(unit()).normalized(); }
  double normal() { return normal_(rng_); }

 private:
  Eigen::Vector3d gaussian() { return {normal(), normal(), normal()}; }
  Eigen::Vector3d scene_offset() {
    return {options_.scene_spread * normal(), options_.scene_spread * normal(), normal()};
  }

  bool visible(const Eigen::Vector3d& X) const {
    const Eigen::Vector3d X2 = R_ * (X - centre2_);
    if (X.z() < kMinDepth || X2.z() < kMinDepth) return false;
    return (X.head<2>() / X.z()).lpNorm<Eigen::Infinity>() < kMaxImageCoordinate &&
           (X2.head<2>() / X2.z()).lpNorm<Eigen::Infinity>() < kMaxImageCoordinate;
  }

  Eigen::Vector2d noise() { return options_.noise * Eigen::Vector2d(normal(), normal()); }
  Eigen::Vector2d project1(const Eigen::Vector3d& X) { return X.head<2>() / X.z() + noise(); }
  Eigen::Vector2d project2(const Eigen::Vector3d& X) {
    const Eigen::Vector3d X2 = R_ * (X - centre2_);
    return X2.head<2>() / X2.z() + noise();
  }

  std::mt19937_64& rng_;
  MinimalInstanceOptions options_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  Eigen::Matrix3d R_;
  Eigen::Vector3d centre2_;
};

}  // namespace

namespace {

MinimalInstance draw_instance(SolverId id, std::mt19937_64& rng,
                              const MinimalInstanceOptions& options) {
  SceneSampler scene(rng, options);
  MinimalInstance instance;
  instance.truth = scene.truth();
  for (int i = 0; i < options.extra_points; ++i) {
    MinimalSample extra;
    scene.add_point(scene.point(), 0, &extra);
    instance.extra_x1.push_back(extra.x1[0]);
    instance.extra_x2.push_back(extra.x2[0]);
  }
  MinimalSample& s = instance.sample;
  s.vp_signs_known = options.orient_vps;
  const SolverInfo& info = solver_info(id);
  Eigen::Vector3d A, B;

  if (info.coplanar || info.lines_coplanar) {
    Eigen::Vector3d origin, u, w;
    scene.plane(&origin, &u, &w);
    const int planar_points = info.coplanar ? info.num_points : 0;
    for (int i = 0; i < planar_points; ++i)
      scene.add_point(scene.plane_point(origin, u, w), i, &s);
    for (int i = planar_points; i < info.num_points; ++i) scene.add_point(scene.point(), i, &s);
    for (int i = 0; i < info.num_lines; ++i)
      scene.add_segment(scene.plane_point(origin, u, w), scene.plane_point(origin, u, w), i, &s);
    if (info.num_vps == 1) scene.add_vp(scene.unit(), 0, &s);
    return instance;
  }

  const Eigen::Vector3d vp_direction = scene.unit();
  switch (id) {
    case SolverId::k5pt:
    case SolverId::k1vp3pt:
    case SolverId::k2vp2pt:
      for (int i = 0; i < info.num_points; ++i) scene.add_point(scene.point(), i, &s);
      break;
    case SolverId::k1vpOrthline2pt:
      scene.segment(scene.orthogonal_unit(vp_direction), &A, &B);
      scene.add_segment(A, B, 0, &s);
      for (int i = 0; i < 2; ++i) scene.add_point(scene.point(), i, &s);
      break;
    case SolverId::k1vp2line1pt: {
      // Two segments through a common point, the first orthogonal to the VP (paper Sec. 5.1).
      const Eigen::Vector3d directions[2] = {scene.orthogonal_unit(vp_direction), scene.unit()};
      Eigen::Vector3d ends[4];
      for (int attempt = 0;; ++attempt) {
        if (attempt == kMaxAttempts) throw Redraw();
        const Eigen::Vector3d X = scene.point();
        if (scene.segment_through(X, directions[0], &ends[0], &ends[1]) &&
            scene.segment_through(X, directions[1], &ends[2], &ends[3]))
          break;
      }
      scene.add_segment(ends[0], ends[1], 0, &s);
      scene.add_segment(ends[2], ends[3], 1, &s);
      scene.add_point(scene.point(), 0, &s);
      break;
    }
    case SolverId::k1vp2ptOrth:
      scene.segment(scene.orthogonal_unit(vp_direction), &A, &B);
      scene.add_point(A, 0, &s);
      scene.add_point(B, 1, &s);
      break;
    default:
      break;
  }
  if (info.num_vps >= 1) scene.add_vp(vp_direction, 0, &s);
  if (info.num_vps == 2) scene.add_vp(scene.unit(), 1, &s);
  return instance;
}

}  // namespace

MinimalInstance generate_minimal_instance(SolverId id, std::mt19937_64& rng,
                                          const MinimalInstanceOptions& options) {
  for (;;) {
    try {
      return draw_instance(id, rng, options);
    } catch (const Redraw&) {
    }
  }
}

}  // namespace hybrid_vo
