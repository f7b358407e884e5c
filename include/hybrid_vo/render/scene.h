#pragma once

// A textured Manhattan interior for the synthetic sequence renderer: a ring corridor around a
// block of rooms, or a single room, built from axis-aligned textured rectangles; or the same
// interior with plain surfaces (low texture). World frame:
// metres, z up, floor at z = 0, the floor plan inside [0, size_x] x [0, size_y]; its x, y, z axes
// are the three Manhattan directions. Everything is deterministic from the seed (std::
// distributions differ between standard libraries, so the scene uses its own generator).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace hybrid_vo {
namespace render {

enum class SceneType {
  kCorridor,  // a closed ring corridor around a central block (four left turns per lap)
  kRoom,      // one rectangular room with a pillar and furniture
};

// Parses "corridor" or "room"; false for anything else.
bool parse_scene_type(const std::string& name, SceneType* type);
const char* to_string(SceneType type);

// What the surfaces look like; the geometry, the lights and the walk are the same either way.
enum class TextureStyle {
  kTextured,  // posters, doors, windows, boards, tiles, acoustic panels: hundreds of corners
  // Low texture: one plain albedo per surface, a few grey levels from its neighbours, lit as
  // the textured ones. Only edges remain: walls, floor, ceiling and plain boxes meeting, a few
  // plain door frames, thin floor joints and flush light panels.
  kPlain,
};

// Parses "textured" or "plain"; false for anything else.
bool parse_texture_style(const std::string& name, TextureStyle* style);
const char* to_string(TextureStyle style);

struct SceneOptions {
  SceneType type = SceneType::kCorridor;
  uint64_t seed = 1;
  double height = 2.7;          // floor to ceiling, metres
  double corridor_width = 2.6;  // kCorridor only
  // Outer size of the floor plan along x and y; 0 picks the type's default (corridor 18 x 12 m,
  // room 9 x 7 m).
  double size_x = 0.0, size_y = 0.0;
  double texels_per_metre = 256.0;  // albedo texture resolution of walls and floors
  int num_furniture = 4;            // cabinets against the walls (0..12)
  TextureStyle texture = TextureStyle::kTextured;
};

// A rectangular albedo texture with its mip chain (level k halves level k - 1 exactly: level 0
// is padded to a multiple of 2^(levels - 1)). Texel (c, r) of level 0 covers [c, c + 1) / tpm
// metres along the quad's u axis and [r, r + 1) / tpm along v. 8-bit, 255 = albedo 1.
struct Texture {
  std::vector<cv::Mat> levels;  // CV_8UC1
  double texels_per_metre = 256.0;
};

enum class SurfaceKind { kFloor, kCeiling, kWall, kFurniture };

// One textured, one-sided, axis-aligned rectangle. Seen from its front (the side `normal` points
// to), u runs to the viewer's right and v downwards (for floors and ceilings: u = +x, and
// v = -y or +y), so texture text reads the right way round. normal = v_axis x u_axis.
struct Quad {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // corner at u = 0, v = 0
  Eigen::Vector3d u_axis = Eigen::Vector3d::UnitX(), v_axis = -Eigen::Vector3d::UnitY();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double size_u = 1.0, size_v = 1.0;  // metres
  SurfaceKind kind = SurfaceKind::kFloor;
  Texture texture;
  // Irradiance at the quad (lights, ambient and corner darkening), sampled every
  // 1 / lightmap_per_metre metres like the texture; multiplies the albedo.
  cv::Mat lightmap;  // CV_32FC1
  double lightmap_per_metre = 16.0;

  int normal_axis() const;  // 0, 1 or 2: the world axis the normal lies on
  // Plane coordinates (u, v) of a world point (on the plane or not).
  Eigen::Vector2d local(const Eigen::Vector3d& X) const;
  Eigen::Vector3d point(double u, double v) const { return origin + u * u_axis + v * v_axis; }
};

// A ceiling light: a Lambertian emitter facing down, drawn as a fixture of this half size.
struct Light {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector2d half_extent = Eigen::Vector2d(0.3, 0.3);  // x, y
  double power = 1.0;
};

// An axis-aligned solid (furniture, pillar); the camera must stay out of it.
struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();
};

// A painted corner of the texture (outer corners of door frames, posters, windows, boards): an
// L-shaped intensity corner at a known world position, for checking the renderer's geometry.
struct Landmark {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  int quad = -1;
};

struct Scene {
  SceneOptions options;  // as given, with the default sizes filled in
  std::vector<Quad> quads;
  std::vector<Light> lights;
  std::vector<Box> boxes;
  // Free floor area: non-overlapping axis-aligned rectangles (min, max) in x, y.
  std::vector<std::array<Eigen::Vector2d, 2>> floor_plan;
  // The camera route: a closed axis-aligned polygon in x, y through the free space, walked from
  // vertex 0 (which lies mid-edge) counter-clockwise; its corners are rounded with this radius.
  std::vector<Eigen::Vector2d> route;
  double route_corner_radius = 1.0;
  // The camera looks this far left of the route's direction (in the room: towards the middle).
  double route_look_left_deg = 0.0;
  std::vector<Landmark> landmarks;

  // True when p is inside the free space with at least `margin` metres to every wall, the
  // floor, the ceiling and every box.
  bool is_free(const Eigen::Vector3d& p, double margin) const;
};

// Builds the scene (a few tenths of a second: the textures are painted at full resolution).
// Throws std::invalid_argument for invalid options.
Scene build_scene(const SceneOptions& options = {});

}  // namespace render
}  // namespace hybrid_vo
