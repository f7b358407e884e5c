#include "hybrid_vo/render/scene.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "painter.h"
#include "plain_surfaces.h"
#include "surfaces.h"

namespace hybrid_vo {
namespace render {
namespace {

using Rect2 = std::array<Eigen::Vector2d, 2>;

// A wall on the boundary of the floor plan: the plane x (axis 0) or y (axis 1) = pos over
// [from, to] along the other axis, facing +axis (facing = +1) or -axis into the free space.
struct WallLine {
  int axis = 0;
  double pos = 0.0, from = 0.0, to = 0.0;
  int facing = 1;
  bool exterior = false;
};

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("render scene: " + what);
}

// The boundary of the union of the plan's rectangles, on the grid of their edges, merged into
// maximal wall segments.
std::vector<WallLine> plan_walls(const std::vector<Rect2>& plan) {
  std::vector<double> xs, ys;
  for (const Rect2& r : plan) {
    xs.insert(xs.end(), {r[0].x(), r[1].x()});
    ys.insert(ys.end(), {r[0].y(), r[1].y()});
  }
  for (auto* v : {&xs, &ys}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
  const int nx = static_cast<int>(xs.size()) - 1, ny = static_cast<int>(ys.size()) - 1;
  auto inside = [&](int i, int j) {
    if (i < 0 || j < 0 || i >= nx || j >= ny) return false;
    const double x = 0.5 * (xs[i] + xs[i + 1]), y = 0.5 * (ys[j] + ys[j + 1]);
    for (const Rect2& r : plan)
      if (x > r[0].x() && x < r[1].x() && y > r[0].y() && y < r[1].y()) return true;
    return false;
  };
  std::vector<WallLine> walls;
  for (int axis = 0; axis < 2; ++axis) {
    const std::vector<double>& lines = axis == 0 ? xs : ys;
    const std::vector<double>& runs = axis == 0 ? ys : xs;
    const int n_lines = static_cast<int>(lines.size()), n_runs = static_cast<int>(runs.size()) - 1;
    for (int i = 0; i < n_lines; ++i) {
      WallLine current;
      bool open = false;
      for (int j = 0; j <= n_runs; ++j) {
        int facing = 0;
        if (j < n_runs) {
          const bool before = axis == 0 ? inside(i - 1, j) : inside(j, i - 1);
          const bool after = axis == 0 ? inside(i, j) : inside(j, i);
          if (before != after) facing = after ? 1 : -1;
        }
        if (open && (facing != current.facing || runs[j] != current.to)) {
          walls.push_back(current);
          open = false;
        }
        if (facing != 0 && !open) {
          current = WallLine{axis, lines[i], runs[j], runs[j + 1], facing, false};
          current.exterior = i == 0 || i == n_lines - 1;
          open = true;
        } else if (facing != 0) {
          current.to = runs[j + 1];
        }
      }
    }
  }
  return walls;
}

// A quad on the plane normal . X = offset covering the box [lo, hi] (flat along the normal),
// with v along v_axis and u = normal x v_axis.
Quad make_quad(const Eigen::Vector3d& normal, const Eigen::Vector3d& v_axis,
               const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, SurfaceKind kind) {
  Quad q;
  q.normal = normal;
  q.v_axis = v_axis;
  q.u_axis = normal.cross(v_axis);
  q.kind = kind;
  // The origin takes the low end along an axis pointing +, the high end along one pointing -.
  for (int k = 0; k < 3; ++k) {
    const double along = q.u_axis[k] + q.v_axis[k];
    q.origin[k] = along < 0.0 ? hi[k] : lo[k];
  }
  q.size_u = std::abs((hi - lo).dot(q.u_axis));
  q.size_v = std::abs((hi - lo).dot(q.v_axis));
  return q;
}

double distance_to_segment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
  return (a + t * ab - p).norm();
}

double distance_to_box_2d(const Eigen::Vector2d& p, const Box& box) {
  const double dx = std::max({box.min.x() - p.x(), 0.0, p.x() - box.max.x()});
  const double dy = std::max({box.min.y() - p.y(), 0.0, p.y() - box.max.y()});
  return std::hypot(dx, dy);
}

// The ends of a wall quad's footprint.
std::array<Eigen::Vector2d, 2> wall_segment(const Quad& q) {
  return {q.origin.head<2>(), q.point(q.size_u, 0.0).head<2>()};
}

double ambient_of(const Quad& q) {
  switch (q.kind) {
    case SurfaceKind::kFloor:
      return 0.36;
    case SurfaceKind::kCeiling:
      return 0.62;
    case SurfaceKind::kWall:
      return 0.42;
    default:
      return q.normal.z() > 0.5 ? 0.4 : 0.42;
  }
}

// Irradiance over a quad: ambient (per kind of surface, standing in for interreflections),
// the ceiling lights, and darkening in concave corners and under furniture.
cv::Mat compute_lightmap(const Quad& q, const Scene& scene, double per_metre) {
  const int cols = std::max(1, static_cast<int>(std::ceil(q.size_u * per_metre)));
  const int rows = std::max(1, static_cast<int>(std::ceil(q.size_v * per_metre)));
  std::vector<std::array<Eigen::Vector2d, 2>> walls;
  std::vector<Eigen::Vector2d> wall_normals;
  for (const Quad& other : scene.quads)
    if (other.kind == SurfaceKind::kWall && &other != &q) {
      walls.push_back(wall_segment(other));
      wall_normals.push_back(other.normal.head<2>());
    }
  const double height = scene.options.height;
  cv::Mat map(rows, cols, CV_32FC1);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const Eigen::Vector3d X = q.point((c + 0.5) / per_metre, (r + 0.5) / per_metre);
      double e = ambient_of(q);
      for (const Light& light : scene.lights) {
        const Eigen::Vector3d d = light.position - X;
        const double d2 = d.squaredNorm() + 0.05, dist = std::sqrt(d2);
        const double cos_r = std::max(0.0, q.normal.dot(d)) / dist;
        const double cos_e = std::max(0.0, d.z()) / dist;
        e += light.power * cos_r * cos_e / d2;
      }
      double shade = 1.0;
      if (q.kind == SurfaceKind::kWall || q.kind == SurfaceKind::kFurniture) {
        if (std::abs(q.normal.z()) < 0.5) shade *= 1.0 - 0.35 * std::exp(-X.z() / 0.12);
        if (q.kind == SurfaceKind::kWall) shade *= 1.0 - 0.25 * std::exp(-(height - X.z()) / 0.15);
      }
      if (q.kind != SurfaceKind::kFurniture || std::abs(q.normal.z()) < 0.5) {
        const double strength = q.kind == SurfaceKind::kCeiling ? 0.2 : 0.3;
        for (size_t k = 0; k < walls.size(); ++k) {
          // Only walls whose free side this point is on make a concave corner with it.
          if (wall_normals[k].dot(X.head<2>() - walls[k][0]) <= 1e-6) continue;
          const double dist = distance_to_segment(X.head<2>(), walls[k][0], walls[k][1]);
          shade *= 1.0 - strength * std::exp(-dist / 0.15);
        }
      }
      if (q.kind == SurfaceKind::kFloor)
        for (const Box& box : scene.boxes)
          shade *= 1.0 - 0.45 * std::exp(-distance_to_box_2d(X.head<2>(), box) / 0.1);
      map.at<float>(r, c) = static_cast<float>(e * shade);
    }
  }
  return map;
}

void add_box_quads(const Box& box, bool with_top, std::vector<Quad>* quads) {
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  for (int axis = 0; axis < 2; ++axis)
    for (int sign : {-1, 1}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = sign;
      Eigen::Vector3d lo = box.min, hi = box.max;
      lo[axis] = hi[axis] = sign > 0 ? box.max[axis] : box.min[axis];
      quads->push_back(make_quad(n, down, lo, hi, SurfaceKind::kFurniture));
    }
  if (with_top) {
    Eigen::Vector3d lo = box.min;
    lo.z() = box.max.z();
    quads->push_back(make_quad(Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitY(), lo, box.max,
                               SurfaceKind::kFurniture));
  }
}

}  // namespace

bool parse_scene_type(const std::string& name, SceneType* type) {
  if (name == "corridor") {
    *type = SceneType::kCorridor;
  } else if (name == "room") {
    *type = SceneType::kRoom;
  } else {
    return false;
  }
  return true;
}

const char* to_string(SceneType type) { return type == SceneType::kCorridor ? "corridor" : "room"; }

bool parse_texture_style(const std::string& name, TextureStyle* style) {
  if (name == "textured") {
    *style = TextureStyle::kTextured;
  } else if (name == "plain") {
    *style = TextureStyle::kPlain;
  } else {
    return false;
  }
  return true;
}

const char* to_string(TextureStyle style) {
  return style == TextureStyle::kTextured ? "textured" : "plain";
}

int Quad::normal_axis() const {
  int axis = 0;
  normal.cwiseAbs().maxCoeff(&axis);
  return axis;
}

Eigen::Vector2d Quad::local(const Eigen::Vector3d& X) const {
  const Eigen::Vector3d d = X - origin;
  return {d.dot(u_axis), d.dot(v_axis)};
}

bool Scene::is_free(const Eigen::Vector3d& p, double margin) const {
  if (!(p.z() >= margin && p.z() <= options.height - margin)) return false;
  bool inside = false;
  for (const Rect2& r : floor_plan)
    inside = inside ||
             (p.x() >= r[0].x() && p.x() <= r[1].x() && p.y() >= r[0].y() && p.y() <= r[1].y());
  if (!inside) return false;
  for (const Quad& q : quads) {
    if (q.kind != SurfaceKind::kWall) continue;
    const auto seg = wall_segment(q);
    if (distance_to_segment(p.head<2>(), seg[0], seg[1]) < margin) return false;
  }
  for (const Box& box : boxes) {
    const Eigen::Vector3d d = (box.min - p).cwiseMax(p - box.max).cwiseMax(0.0);
    if (d.norm() < margin) return false;
  }
  return true;
}

Scene build_scene(const SceneOptions& options_in) {
  SceneOptions o = options_in;
  const bool corridor = o.type == SceneType::kCorridor;
  if (o.size_x == 0.0) o.size_x = corridor ? 18.0 : 9.0;
  if (o.size_y == 0.0) o.size_y = corridor ? 12.0 : 7.0;
  check(std::isfinite(o.height) && o.height >= 2.2 && o.height <= 6.0,
        "height must be in [2.2, 6] m");
  check(std::isfinite(o.texels_per_metre) && o.texels_per_metre >= 32.0 &&
            o.texels_per_metre <= 1024.0,
        "texels_per_metre must be in [32, 1024]");
  check(o.num_furniture >= 0 && o.num_furniture <= 12, "num_furniture must be in [0, 12]");
  const double w = o.corridor_width;
  if (corridor) {
    check(std::isfinite(w) && w >= 1.8 && w <= 6.0, "corridor_width must be in [1.8, 6] m");
    check(std::isfinite(o.size_x) && std::isfinite(o.size_y) && o.size_x >= 2.0 * w + 2.5 &&
              o.size_y >= 2.0 * w + 2.5 && o.size_x <= 60.0 && o.size_y <= 60.0,
          "corridor size must be in [2 * width + 2.5, 60] m");
  } else {
    check(std::isfinite(o.size_x) && std::isfinite(o.size_y) && o.size_x >= 5.5 &&
              o.size_y >= 5.5 && o.size_x <= 30.0 && o.size_y <= 30.0,
          "room size must be in [5.5, 30] m");
  }
  Rng rng(hash_mix(o.seed, 0x5CE4E));
  Scene scene;
  scene.options = o;
  const double X = o.size_x, Y = o.size_y, H = o.height;

  // Floor plan and route.
  if (corridor) {
    scene.floor_plan = {Rect2{{{0, 0}, {X, w}}}, Rect2{{{0, Y - w}, {X, Y}}},
                        Rect2{{{0, w}, {w, Y - w}}}, Rect2{{{X - w, w}, {X, Y - w}}}};
    // Along the corridors' centre lines, starting 4.5 m before the first (left) turn.
    const double h = 0.5 * w;
    scene.route_corner_radius = std::min(1.0, h - 0.2);
    const double start = std::max(h + scene.route_corner_radius + 0.1, X - h - 4.5);
    scene.route = {{start, h}, {X - h, h}, {X - h, Y - h}, {h, Y - h}, {h, h}};
  } else {
    scene.floor_plan = {Rect2{{{0, 0}, {X, Y}}}};
    const double m = 1.6;
    scene.route = {{0.5 * X, m}, {X - m, m}, {X - m, Y - m}, {m, Y - m}, {m, m}};
    scene.route_corner_radius = 1.0;
    scene.route_look_left_deg = 25.0;
  }

  // Walls first (their quads locate the furniture), then the furniture.
  const std::vector<WallLine> lines = plan_walls(scene.floor_plan);
  std::vector<Quad> wall_quads;
  for (const WallLine& l : lines) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero(), lo, hi;
    n[l.axis] = l.facing;
    const int run = 1 - l.axis;
    lo.setZero();
    hi.setZero();
    lo[l.axis] = hi[l.axis] = l.pos;
    lo[run] = l.from;
    hi[run] = l.to;
    hi.z() = H;
    wall_quads.push_back(make_quad(n, -Eigen::Vector3d::UnitZ(), lo, hi, SurfaceKind::kWall));
  }
  std::vector<WallLayout> layouts(lines.size());
  for (size_t i = 0; i < lines.size(); ++i) {
    layouts[i].length = wall_quads[i].size_u;
    layouts[i].height = H;
    layouts[i].exterior = lines[i].exterior;
  }
  std::vector<double> cabinet_albedo;
  std::vector<Eigen::Vector3d> cabinet_front;
  for (int f = 0, attempts = 0; f < o.num_furniture && attempts < 200; ++attempts) {
    const int i = rng.uniform_int(0, static_cast<int>(lines.size()) - 1);
    if (corridor && !lines[i].exterior) continue;
    const double end_margin = corridor ? w + 0.6 : 0.4;
    const double width = rng.uniform(0.6, 1.4), depth = rng.uniform(0.4, 0.5);
    const double height = rng.uniform(0.75, 1.2);
    const double L = layouts[i].length;
    if (L - 2.0 * end_margin < width) continue;
    const double u0 = rng.uniform(end_margin, L - end_margin - width);
    bool clash = false;
    for (const auto& [a, b] : layouts[i].blocked)
      clash = clash || (u0 < b + 0.4 && u0 + width > a - 0.4);
    if (clash) continue;
    const Quad& wall = wall_quads[i];
    const Eigen::Vector3d a = wall.point(u0, H) + 0.005 * wall.normal;
    const Eigen::Vector3d b = wall.point(u0 + width, H - height) + (0.005 + depth) * wall.normal;
    scene.boxes.push_back(Box{a.cwiseMin(b), a.cwiseMax(b)});
    layouts[i].blocked.emplace_back(u0, u0 + width);
    layouts[i].blocked_height = std::max(layouts[i].blocked_height, height);
    cabinet_albedo.push_back(rng.chance(0.5) ? rng.uniform(0.35, 0.5) : rng.uniform(0.6, 0.8));
    cabinet_front.push_back(wall.normal);
    ++f;
  }
  const size_t num_cabinets = scene.boxes.size();
  if (!corridor)
    scene.boxes.push_back(Box{Eigen::Vector3d(0.5 * X - 0.25, 0.5 * Y - 0.25, 0.0),
                              Eigen::Vector3d(0.5 * X + 0.25, 0.5 * Y + 0.25, H)});

  // Ceiling lights: along each corridor strip, or on a grid in the room.
  const double light_z = H - 0.02, power = 1.6;
  if (corridor) {
    for (const Rect2& r : scene.floor_plan) {
      const Eigen::Vector2d size = r[1] - r[0], centre = 0.5 * (r[0] + r[1]);
      const int along = size.x() >= size.y() ? 0 : 1;
      const Eigen::Vector2d half =
          along == 0 ? Eigen::Vector2d(0.3, 0.6) : Eigen::Vector2d(0.6, 0.3);
      const int n = std::max(1, static_cast<int>(std::floor(size[along] / 2.4)));
      for (int k = 0; k < n; ++k) {
        Eigen::Vector2d p = centre;
        p[along] = r[0][along] + (k + 0.5) * size[along] / n;
        scene.lights.push_back(Light{Eigen::Vector3d(p.x(), p.y(), light_z), half, power});
      }
    }
  } else {
    const int nx = std::max(1, static_cast<int>(std::round(X / 3.0)));
    const int ny = std::max(1, static_cast<int>(std::round(Y / 3.0)));
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j)
        scene.lights.push_back(
            Light{Eigen::Vector3d((i + 0.5) * X / nx, (j + 0.5) * Y / ny, light_z),
                  Eigen::Vector2d(0.6, 0.3), power});
  }

  // Quads: floors, ceilings, walls, furniture; then their textures.
  for (const Rect2& r : scene.floor_plan) {
    scene.quads.push_back(make_quad(Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitY(),
                                    Eigen::Vector3d(r[0].x(), r[0].y(), 0.0),
                                    Eigen::Vector3d(r[1].x(), r[1].y(), 0.0), SurfaceKind::kFloor));
  }
  for (const Rect2& r : scene.floor_plan) {
    scene.quads.push_back(make_quad(-Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(),
                                    Eigen::Vector3d(r[0].x(), r[0].y(), H),
                                    Eigen::Vector3d(r[1].x(), r[1].y(), H), SurfaceKind::kCeiling));
  }
  const size_t first_wall = scene.quads.size();
  scene.quads.insert(scene.quads.end(), wall_quads.begin(), wall_quads.end());
  const size_t first_box = scene.quads.size();
  for (size_t b = 0; b < scene.boxes.size(); ++b)
    add_box_quads(scene.boxes[b], b < num_cabinets, &scene.quads);

  const double tpm = o.texels_per_metre;
  FloorStyle floor;
  floor.seed = rng.next();
  floor.planks = !corridor;
  floor.tile = corridor ? (rng.chance(0.5) ? 0.5 : 0.4) : rng.uniform(0.14, 0.2);
  floor.base = corridor ? rng.uniform(0.45, 0.6) : rng.uniform(0.35, 0.45);
  floor.checker = corridor && rng.chance(0.4);
  if (!corridor) {
    floor.rug = true;
    floor.rug_min = Eigen::Vector2d(0.5 * X - 2.0, 0.5 * Y + 0.6);
    floor.rug_max = Eigen::Vector2d(0.5 * X + 1.0, 0.5 * Y + 1.7);
  }
  const uint64_t ceiling_seed = rng.next();
  std::vector<std::vector<Eigen::Vector2d>> corners(scene.quads.size());
  // Which box a furniture quad belongs to: cabinets have four sides and a top, the pillar four
  // sides.
  auto box_of = [&](size_t quad) {
    size_t box = 0, first = first_box;
    for (; box < scene.boxes.size(); ++box) {
      const size_t faces = box < num_cabinets ? 5 : 4;
      if (quad < first + faces) break;
      first += faces;
    }
    return box;
  };
  const bool plain = o.texture == TextureStyle::kPlain;
  for (size_t i = 0; i < scene.quads.size(); ++i) {
    Quad& q = scene.quads[i];
    const double albedo = q.kind == SurfaceKind::kCeiling ? 0.74 : 0.5;
    Canvas canvas(q.size_u, q.size_v, tpm, albedo);
    Rng surface(hash_mix(o.seed, 1000 + i));
    if (plain) {
      if (q.kind == SurfaceKind::kFloor) {
        paint_plain_floor(&canvas, q, floor.seed);
      } else if (q.kind == SurfaceKind::kCeiling) {
        paint_plain_ceiling(&canvas, q, scene.lights);
      } else if (i < first_box) {
        paint_plain_wall(&canvas, layouts[i - first_wall], surface, &corners[i]);
      } else {
        canvas.rect(0.0, 0.0, q.size_u, q.size_v, plain_box_albedo(hash_mix(o.seed, box_of(i))));
      }
    } else if (q.kind == SurfaceKind::kFloor) {
      paint_floor(&canvas, q, floor);
    } else if (q.kind == SurfaceKind::kCeiling) {
      paint_ceiling(&canvas, q, scene.lights, hash_mix(ceiling_seed, i));
    } else if (i < first_box) {
      paint_wall(&canvas, layouts[i - first_wall], surface, &corners[i]);
    } else {
      const size_t box = box_of(i);
      if (box < num_cabinets) {
        // The front faces the way of the wall the cabinet stands against.
        const bool front = q.normal.dot(cabinet_front[box]) > 0.5;
        paint_cabinet_face(&canvas, cabinet_albedo[box], front, q.normal.z() > 0.5, surface);
      } else {
        paint_pillar_face(&canvas, surface, &corners[i]);
      }
    }
    q.texture = canvas.finish();
  }
  for (size_t i = 0; i < scene.quads.size(); ++i) {
    Quad& q = scene.quads[i];
    q.lightmap = compute_lightmap(q, scene, q.lightmap_per_metre);
    for (const Eigen::Vector2d& c : corners[i])
      scene.landmarks.push_back(Landmark{q.point(c.x(), c.y()), static_cast<int>(i)});
  }
  return scene;
}

}  // namespace render
}  // namespace hybrid_vo
