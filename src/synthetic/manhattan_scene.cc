#include "hybrid_vo/synthetic/manhattan_scene.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/geometry/vanishing_point.h"

namespace hybrid_vo {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr double kMinDepth = 1.5;  // metres, in both cameras
// True projections stay this far inside the image, so that noise seldom pushes them out.
constexpr double kMarginPx = 2.0;
constexpr double kBehind = 30.0;               // faces extend this far behind camera 1
constexpr double kFreeClearance = 0.25;        // free-volume points stay off every plane
constexpr double kCameraClearance = 0.5;       // camera 2 stays this far inside the box
constexpr double kFaceTolerance = 1e-7;        // metres, for points computed on a face
constexpr double kMinJunctionAngleDeg = 15.0;  // between the segments of a pair, both images
constexpr int kMaxDraws = 2000;                // per camera, point, segment or pair
constexpr int kMaxScenes = 50;

// Thrown when a draw keeps failing: the whole scene is redrawn rather than looping forever.
struct Redraw {};

// A finite face of the box in Manhattan ("world") coordinates w, with X_camera1 = directions * w.
// Axis 0 points down, 1 forward, 2 right; the normal of the face is world axis `axis`.
struct Face {
  int axis = 0;
  double offset = 0.0;
  Eigen::Vector3d lo, hi;

  bool contains(const Eigen::Vector3d& w) const {
    return ((w - lo).array() >= -kFaceTolerance).all() &&
           ((hi - w).array() >= -kFaceTolerance).all();
  }
};

struct Segment {
  Eigen::Vector3d A, B;  // camera 1
  int face = -1, direction = -1;
};

struct Pair {
  Segment a, b;
  JunctionType type = JunctionType::kX;
  Eigen::Vector3d point;
};

class SceneBuilder {
 public:
  SceneBuilder(std::mt19937_64& rng, const ManhattanSceneOptions& options)
      : rng_(rng), options_(options) {
    camera_ = PinholeCamera(options.focal_px, options.focal_px, 0.5 * options.width,
                            0.5 * options.height, options.width, options.height);
  }

  ManhattanScene build() {
    draw_frame();
    draw_box();
    draw_camera2();
    ManhattanScene scene;
    scene.camera1 = scene.camera2 = camera_;
    scene.directions = D_;
    scene.baseline_m = t_.norm();
    scene.truth = RelativePose(R_, scene.baseline_m > 0.0 ? Eigen::Vector3d(t_ / scene.baseline_m)
                                                          : Eigen::Vector3d::Zero());
    for (const Face& f : faces_) scene.planes.push_back({D_.col(f.axis), f.offset, f.axis});
    add_points(&scene);
    add_segments(&scene);
    add_vps(&scene);
    return scene;
  }

 private:
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  int uniform_int(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  bool coin() { return uniform_int(2) == 1; }
  double normal() { return normal_(rng_); }
  Eigen::Vector3d random_unit() {
    for (;;) {
      const Eigen::Vector3d g(normal(), normal(), normal());
      if (g.norm() > 1e-6) return g.normalized();
    }
  }

  // Upright-ish: the vertical direction within 10 degrees of camera 1's y axis, the scene's
  // forward axis within 35 degrees of the optical axis in yaw.
  void draw_frame() {
    Eigen::Matrix3d D0;
    D0.col(0) = Eigen::Vector3d::UnitY();
    D0.col(1) = Eigen::Vector3d::UnitZ();
    D0.col(2) = Eigen::Vector3d::UnitX();
    D_ = rotation_about(Eigen::Vector3d::UnitZ(), uniform(-10.0, 10.0) * kDeg) *
         rotation_about(Eigen::Vector3d::UnitX(), uniform(-10.0, 10.0) * kDeg) *
         rotation_about(Eigen::Vector3d::UnitY(), uniform(-35.0, 35.0) * kDeg) * D0;
  }

  // Camera 1 at the origin of a box: ground 1.2-2 m below, walls 2.5-6 m to each side, back wall
  // 8-15 m ahead; either a ceiling 1-2.5 m above (indoor) or walls 6-20 m tall under open sky.
  void draw_box() {
    const double ground = uniform(1.2, 2.0);
    const double left = uniform(2.5, 6.0), right = uniform(2.5, 6.0);
    const double back = uniform(8.0, 15.0);
    const bool ceiling = coin();
    const double top = ceiling ? uniform(1.0, 2.5) : uniform(6.0, 20.0);
    box_lo_ = Eigen::Vector3d(-top, -kBehind, -left);
    box_hi_ = Eigen::Vector3d(ground, back, right);
    faces_.clear();
    auto add_face = [&](int axis, double offset) {
      Face f;
      f.axis = axis;
      f.offset = offset;
      f.lo = box_lo_;
      f.hi = box_hi_;
      f.lo[axis] = f.hi[axis] = offset;
      faces_.push_back(f);
    };
    add_face(0, ground);
    if (ceiling) add_face(0, -top);
    add_face(2, -left);
    add_face(2, right);
    add_face(1, back);
  }

  // Rotation about a random axis; centre at `baseline` towards the front half-space of camera 1
  // (optical-axis component >= 0.25 of it), inside the box.
  void draw_camera2() {
    for (int draw = 0; draw < kMaxDraws; ++draw) {
      const double angle = uniform(0.0, options_.max_rotation_deg) * kDeg;
      const Eigen::Matrix3d R = rotation_about(random_unit(), angle);
      Eigen::Vector3d u = random_unit();
      u.z() = std::abs(u.z());
      if (u.z() < 0.25) continue;
      const Eigen::Vector3d c2 = options_.baseline * u;
      const Eigen::Vector3d w = D_.transpose() * c2;
      if (((w - box_lo_).array() < kCameraClearance).any() ||
          ((box_hi_ - w).array() < kCameraClearance).any())
        continue;
      R_ = R;
      t_ = -R * c2;
      return;
    }
    throw Redraw();
  }

  Eigen::Vector2d project1(const Eigen::Vector3d& X) const {
    return camera_.denormalize(X.head<2>() / X.z());
  }
  Eigen::Vector2d project2(const Eigen::Vector3d& X) const {
    const Eigen::Vector3d X2 = R_ * X + t_;
    return camera_.denormalize(X2.head<2>() / X2.z());
  }
  bool inside_margin(const Eigen::Vector2d& x) const {
    return x.x() >= kMarginPx && x.y() >= kMarginPx && x.x() <= camera_.width - 1.0 - kMarginPx &&
           x.y() <= camera_.height - 1.0 - kMarginPx;
  }
  bool visible(const Eigen::Vector3d& X) const {
    const Eigen::Vector3d X2 = R_ * X + t_;
    return X.z() >= kMinDepth && X2.z() >= kMinDepth && inside_margin(project1(X)) &&
           inside_margin(project2(X));
  }

  Eigen::Vector2d random_pixel(double margin) {
    return {uniform(margin, camera_.width - 1.0 - margin),
            uniform(margin, camera_.height - 1.0 - margin)};
  }

  // First face hit by the ray of camera-1 pixel x (camera 1 is inside the convex box, so the
  // first hit is the visible surface); false for the open sky. *depth is camera-1 depth.
  bool raycast(const Eigen::Vector2d& x, int* face, double* depth) const {
    const Eigen::Vector3d ray = homogeneous(camera_.normalize(x));
    const Eigen::Vector3d ray_w = D_.transpose() * ray;
    *face = -1;
    for (int i = 0; i < static_cast<int>(faces_.size()); ++i) {
      const Face& f = faces_[i];
      if (std::abs(ray_w[f.axis]) < 1e-12) continue;
      const double s = f.offset / ray_w[f.axis];
      if (!(s > 0.0) || (*face >= 0 && s >= *depth)) continue;
      if (!f.contains(s * ray_w)) continue;
      *face = i;
      *depth = s;
    }
    return *face >= 0;
  }

  // A uniformly random visible surface point in image 1, seen by camera 2.
  void surface_point(Eigen::Vector3d* X, int* face) {
    for (int draw = 0; draw < kMaxDraws; ++draw) {
      const Eigen::Vector2d x = random_pixel(kMarginPx);
      double depth = 0.0;
      if (!raycast(x, face, &depth)) continue;
      *X = depth * homogeneous(camera_.normalize(x));
      if (visible(*X)) return;
    }
    throw Redraw();
  }

  Eigen::Vector3d free_point() {
    for (int draw = 0; draw < kMaxDraws; ++draw) {
      const Eigen::Vector2d x = random_pixel(kMarginPx);
      int face;
      double depth = 0.0;
      if (!raycast(x, &face, &depth) || depth <= kMinDepth) continue;
      const Eigen::Vector3d X = uniform(kMinDepth, depth) * homogeneous(camera_.normalize(x));
      const Eigen::Vector3d w = D_.transpose() * X;
      bool clear = true;
      for (const Face& f : faces_)
        clear = clear && std::abs(w[f.axis] - f.offset) >= kFreeClearance;
      if (clear && visible(X)) return X;
    }
    throw Redraw();
  }

  // B = X + s u (s > 0) whose image-1 projection lies `length` px from X's; false when the
  // vanishing point of u is nearer than that. Closed form: |x(s) - x(0)| = s g / (z + s u_z).
  bool extend(const Eigen::Vector3d& X, const Eigen::Vector3d& u, double length,
              Eigen::Vector3d* B) const {
    const double z = X.z();
    const Eigen::Vector2d a(camera_.fx * (u.x() * z - X.x() * u.z()),
                            camera_.fy * (u.y() * z - X.y() * u.z()));
    const double g = a.norm() / z;
    const double denominator = g - length * u.z();
    if (!(denominator > 1e-9)) return false;
    *B = X + (length * z / denominator) * u;
    return true;
  }

  bool segment_ok(const Segment& s) const {
    const Face& f = faces_[s.face];
    return f.contains(D_.transpose() * s.A) && f.contains(D_.transpose() * s.B) && visible(s.A) &&
           visible(s.B) && (project2(s.A) - project2(s.B)).norm() >= 0.5 * options_.min_segment_px;
  }

  double segment_length() { return uniform(options_.min_segment_px, options_.max_segment_px); }

  // Direction index and signed unit vector of one of the face's two in-plane Manhattan axes.
  int in_plane_direction(int face, int which) const {
    const int axis = faces_[face].axis;
    return (axis + 1 + which) % 3;
  }
  Eigen::Vector3d signed_direction(int k) {
    return coin() ? D_.col(k) : Eigen::Vector3d(-D_.col(k));
  }

  // The direction first, so that each direction gets about a third of the single segments
  // (sampling by image area would leave few vertical ones when the ground fills the view).
  Segment single_segment() {
    const int direction = uniform_int(3);
    for (int draw = 0; draw < kMaxDraws; ++draw) {
      Segment s;
      surface_point(&s.A, &s.face);
      if (faces_[s.face].axis == direction) continue;
      s.direction = direction;
      if (!extend(s.A, signed_direction(s.direction), segment_length(), &s.B)) continue;
      if (segment_ok(s)) return s;
    }
    throw Redraw();
  }

  // A segment along u through J (crossing: J at 25-75 % of its image length) or ending at J.
  bool arm(const Eigen::Vector3d& J, const Eigen::Vector3d& u, bool crossing, Segment* s) {
    const double length = segment_length();
    if (!crossing) {
      s->A = J;
      if (!extend(J, u, length, &s->B)) return false;
    } else {
      const double fraction = uniform(0.25, 0.75);
      if (!extend(J, -u, (1.0 - fraction) * length, &s->A) ||
          !extend(J, u, fraction * length, &s->B))
        return false;
    }
    if (coin()) std::swap(s->A, s->B);  // so that J is not always p1
    return segment_ok(*s);
  }

  // Near the VPs two Manhattan directions can look almost parallel, and their junction would be
  // ill-conditioned: noise of a pixel would move it along the segments by many.
  bool crossing_angle_ok(const Pair& p) const {
    const double min_sine = std::sin(kMinJunctionAngleDeg * kDeg);
    auto sine = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
      return std::abs(u.x() * v.y() - u.y() * v.x()) / (u.norm() * v.norm());
    };
    return sine(project1(p.a.B) - project1(p.a.A), project1(p.b.B) - project1(p.b.A)) >= min_sine &&
           sine(project2(p.a.B) - project2(p.a.A), project2(p.b.B) - project2(p.b.A)) >= min_sine;
  }

  Pair junction_pair() {
    for (int draw = 0; draw < kMaxDraws; ++draw) {
      Pair p;
      int face;
      surface_point(&p.point, &face);
      const int first = uniform_int(2);
      p.a.face = p.b.face = face;
      p.a.direction = in_plane_direction(face, first);
      p.b.direction = in_plane_direction(face, 1 - first);
      p.type = static_cast<JunctionType>(uniform_int(3));
      if (arm(p.point, signed_direction(p.a.direction), p.type != JunctionType::kL, &p.a) &&
          arm(p.point, signed_direction(p.b.direction), p.type == JunctionType::kX, &p.b) &&
          crossing_angle_ok(p))
        return p;
    }
    throw Redraw();
  }

  // Gaussian noise, redrawn (then clamped) so that the pixel stays inside the image.
  Eigen::Vector2d noisy(const Eigen::Vector2d& x) {
    const double sigma = options_.noise_px;
    if (sigma == 0.0) return x;
    for (int draw = 0; draw < 100; ++draw) {
      const Eigen::Vector2d y = x + sigma * Eigen::Vector2d(normal(), normal());
      if (camera_.in_image(y)) return y;
    }
    return {std::clamp(x.x(), 0.0, camera_.width - 1.0),
            std::clamp(x.y(), 0.0, camera_.height - 1.0)};
  }

  std::vector<int> permutation(int n) {
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng_);
    return order;
  }

  static int rounded(double x) { return static_cast<int>(std::lround(x)); }

  void add_points(ManhattanScene* scene) {
    const int n = options_.num_points;
    const int n_out = rounded(options_.point_outlier_ratio * n);
    const int n_in = n - n_out;
    const int planar_in = rounded(options_.planar_point_fraction * n_in);
    const int planar_out = rounded(options_.planar_point_fraction * n_out);
    std::vector<PointMatch> matches(n);
    std::vector<Eigen::Vector3d> X(n);
    std::vector<int> plane(n, -1);
    for (int i = 0; i < n; ++i) {
      const bool inlier = i < n_in;
      const bool planar = inlier ? i < planar_in : i - n_in < planar_out;
      if (planar)
        surface_point(&X[i], &plane[i]);
      else
        X[i] = free_point();
      matches[i].x1 = noisy(project1(X[i]));
      matches[i].x2 = noisy(project2(X[i]));
      if (!inlier) matches[i].x2 = random_pixel(0.0);
    }
    for (int i : permutation(n)) {
      scene->matches.points.push_back(matches[i]);
      scene->point_inlier.push_back(i < n_in);
      scene->point_plane.push_back(plane[i]);
      scene->points3d.push_back(X[i]);
    }
  }

  void add_segments(ManhattanScene* scene) {
    const int n = options_.num_segments;
    const int n_out = rounded(options_.line_outlier_ratio * n);
    const int n_in = n - n_out;
    const int n_pairs = std::min(rounded(options_.junction_fraction * n_in / 2.0), n_in / 2);
    std::vector<Segment> segments;
    std::vector<Pair> pairs;
    for (int i = 0; i < n_pairs; ++i) {
      pairs.push_back(junction_pair());
      segments.push_back(pairs.back().a);
      segments.push_back(pairs.back().b);
    }
    while (static_cast<int>(segments.size()) < n) segments.push_back(single_segment());

    std::vector<LineMatch> matches(n);
    for (int i = 0; i < n; ++i) {
      const Segment& s = segments[i];
      matches[i].s1 = LineSegment(noisy(project1(s.A)), noisy(project1(s.B)));
      matches[i].s2 = LineSegment(noisy(project2(s.A)), noisy(project2(s.B)));
    }
    // Wrong matches take the image-2 segment of another segment (a spare one if there is none).
    LineSegment spare;
    if (n_out > 0 && n == 1) {
      const Segment s = single_segment();
      spare = LineSegment(noisy(project2(s.A)), noisy(project2(s.B)));
    }
    std::vector<LineSegment> image2(n);
    for (int i = 0; i < n; ++i) image2[i] = matches[i].s2;
    for (int i = n_in; i < n; ++i) {
      if (n == 1) {
        matches[i].s2 = spare;
        continue;
      }
      int other = uniform_int(n - 1);
      if (other >= i) ++other;
      matches[i].s2 = image2[other];
    }

    const std::vector<int> order = permutation(n);
    std::vector<int> new_index(n);
    for (int k = 0; k < n; ++k) {
      const int i = order[k];
      new_index[i] = k;
      const Segment& s = segments[i];
      scene->matches.lines.push_back(matches[i]);
      scene->line_inlier.push_back(i < n_in);
      scene->line_plane.push_back(s.face);
      scene->line_direction.push_back(s.direction);
      scene->matches.line_vp.push_back(s.direction < options_.num_vps ? s.direction : -1);
      scene->segments3d.push_back({s.A, s.B});
    }
    for (int i = 0; i < n_pairs; ++i) {
      ManhattanJunction j;
      j.segments = {new_index[2 * i], new_index[2 * i + 1]};
      j.type = pairs[i].type;
      j.point = pairs[i].point;
      scene->junctions.push_back(j);
    }
  }

  // Rotation of unit d by exactly `angle` about a random axis orthogonal to it.
  Eigen::Vector3d perturb(const Eigen::Vector3d& d, double angle) {
    for (;;) {
      const Eigen::Vector3d axis = d.cross(random_unit());
      if (axis.norm() > 1e-3) return rotation_about(axis.normalized(), angle) * d;
    }
  }

  void add_vps(ManhattanScene* scene) {
    const Eigen::Matrix3d Kt = camera_.K().transpose();  // pixel line -> normalised line
    for (int k = 0; k < options_.num_vps; ++k) {
      VpMatch vp;
      vp.d1 = D_.col(k);
      vp.d2 = R_ * vp.d1;
      if (options_.lines_per_vp_fit > 0) {
        std::vector<Eigen::Vector3d> lines1, lines2;
        for (size_t i = 0; i < scene->matches.lines.size(); ++i) {
          if (static_cast<int>(lines1.size()) == options_.lines_per_vp_fit) break;
          if (!scene->line_inlier[i] || scene->line_direction[i] != k) continue;
          lines1.push_back(Kt * scene->matches.lines[i].s1.line());
          lines2.push_back(Kt * scene->matches.lines[i].s2.line());
        }
        const Eigen::Vector3d v1 = vanishing_point_from_lines(lines1);
        const Eigen::Vector3d v2 = vanishing_point_from_lines(lines2);
        if (v1.norm() > 0.5 && v2.norm() > 0.5) {
          vp.d1 = v1.dot(vp.d1) >= 0.0 ? v1 : Eigen::Vector3d(-v1);
          vp.d2 = v2.dot(vp.d2) >= 0.0 ? v2 : Eigen::Vector3d(-v2);
        }
      }
      if (options_.vp_noise_deg > 0.0) {
        vp.d1 = perturb(vp.d1, options_.vp_noise_deg * kDeg);
        vp.d2 = perturb(vp.d2, options_.vp_noise_deg * kDeg);
      }
      if (options_.orient_vps) {
        if (vp.d2.dot(R_ * vp.d1) < 0.0) vp.d2 = -vp.d2;
        vp.sign_known = true;
      } else {
        if (coin()) vp.d1 = -vp.d1;
        if (coin()) vp.d2 = -vp.d2;
      }
      scene->matches.vps.push_back(vp);
    }
  }

  std::mt19937_64& rng_;
  const ManhattanSceneOptions& options_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  PinholeCamera camera_;
  Eigen::Matrix3d D_ = Eigen::Matrix3d::Identity();  // Manhattan directions, camera 1
  Eigen::Vector3d box_lo_, box_hi_;                  // world coordinates
  std::vector<Face> faces_;
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();  // metric
};

void check_options(const ManhattanSceneOptions& o) {
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("ManhattanSceneOptions: ") + what);
  };
  auto fraction = [](double x) { return x >= 0.0 && x <= 1.0; };
  require(o.num_points >= 0 && o.num_segments >= 0, "negative count");
  require(fraction(o.planar_point_fraction) && fraction(o.point_outlier_ratio) &&
              fraction(o.line_outlier_ratio) && fraction(o.junction_fraction),
          "fraction outside [0, 1]");
  require(o.num_vps >= 0 && o.num_vps <= 3, "num_vps outside 0..3");
  require(o.lines_per_vp_fit >= 0, "negative lines_per_vp_fit");
  require(o.noise_px >= 0.0 && std::isfinite(o.noise_px), "invalid noise_px");
  require(o.vp_noise_deg >= 0.0 && o.vp_noise_deg <= 90.0, "vp_noise_deg outside [0, 90]");
  require(o.focal_px > 0.0 && std::isfinite(o.focal_px), "invalid focal_px");
  require(o.width > 2.0 * kMarginPx + 1.0 && o.height > 2.0 * kMarginPx + 1.0, "image too small");
  require(o.baseline >= 0.0 && std::isfinite(o.baseline), "invalid baseline");
  require(o.max_rotation_deg >= 0.0 && o.max_rotation_deg <= 180.0,
          "max_rotation_deg outside [0, 180]");
  require(o.min_segment_px > 0.0 && o.min_segment_px <= o.max_segment_px &&
              std::isfinite(o.max_segment_px),
          "invalid segment length range");
}

}  // namespace

ManhattanScene generate_manhattan_scene(std::mt19937_64& rng,
                                        const ManhattanSceneOptions& options) {
  check_options(options);
  for (int attempt = 0; attempt < kMaxScenes; ++attempt) {
    try {
      return SceneBuilder(rng, options).build();
    } catch (const Redraw&) {
    }
  }
  throw std::runtime_error("generate_manhattan_scene: no scene fits the options");
}

}  // namespace hybrid_vo
