#pragma once

// What the renderer's surfaces look like: walls with doors, windows, posters and boards; tiled
// or planked floors; suspended ceilings with lights; furniture. Each painter draws on a Canvas
// in the quad's (u, v) metres and reports the painted corners it guarantees to be sharp.

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/render/scene.h"
#include "painter.h"

namespace hybrid_vo {
namespace render {

struct WallLayout {
  double length = 1.0, height = 2.7;
  bool exterior = false;  // may have windows
  // Stretches of u with furniture in front, up to blocked_height: no doors or radiators there,
  // and boards or posters above it.
  std::vector<std::pair<double, double>> blocked;
  double blocked_height = 0.0;
};

// Paints a wall; appends the (u, v) of its sharp painted corners to `corners`.
void paint_wall(Canvas* canvas, const WallLayout& layout, Rng& rng,
                std::vector<Eigen::Vector2d>* corners);

struct FloorStyle {
  bool planks = false;   // wooden planks along x, else square tiles
  double tile = 0.5;     // tile size (planks: width), metres
  double base = 0.45;    // mean albedo
  bool checker = false;  // tiles alternate between two albedos
  uint64_t seed = 1;     // the pattern is anchored to the world, so quads join seamlessly
  bool rug = false;      // a rug at rug_min..rug_max (x, y)
  Eigen::Vector2d rug_min = Eigen::Vector2d::Zero(), rug_max = Eigen::Vector2d::Zero();
};

// Floor quads have u = +x, v = -y; ceiling quads u = +x, v = +y.
void paint_floor(Canvas* canvas, const Quad& quad, const FloorStyle& style);
void paint_ceiling(Canvas* canvas, const Quad& quad, const std::vector<Light>& lights,
                   uint64_t seed);

// A face of a cabinet: `front` gets drawers or doors, `top` a few objects.
void paint_cabinet_face(Canvas* canvas, double albedo, bool front, bool top, Rng& rng);
// A face of a pillar, with a poster when it is wide enough; appends the poster's corners.
void paint_pillar_face(Canvas* canvas, Rng& rng, std::vector<Eigen::Vector2d>* corners);

}  // namespace render
}  // namespace hybrid_vo
