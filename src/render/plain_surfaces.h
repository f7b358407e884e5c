#pragma once

// The low-texture look of the renderer's surfaces (TextureStyle::kPlain): one plain albedo per
// surface, a few grey levels apart, so that only the edges remain: where walls, floor, ceiling
// and boxes meet, plain door frames on the walls (a few corners), joints on the floor and the
// light panels on the ceiling. What a point tracker finds there is the sensor noise or a handful
// of corners; what lines, junctions and VPs find is all there is.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/render/scene.h"
#include "painter.h"
#include "surfaces.h"

namespace hybrid_vo {
namespace render {

// A plain wall with a few plain doors (frame and leaf a few grey levels off the wall); appends
// the (u, v) of the frames' top outer corners to `corners`.
void paint_plain_wall(Canvas* canvas, const WallLayout& layout, Rng& rng,
                      std::vector<Eigen::Vector2d>* corners);

// A plain floor with thin joints on a world-anchored grid (floor quads: u = +x, v = -y).
void paint_plain_floor(Canvas* canvas, const Quad& quad, uint64_t seed);

// A plain ceiling with flush light panels, slightly brighter (ceiling quads: u = +x, v = +y).
void paint_plain_ceiling(Canvas* canvas, const Quad& quad, const std::vector<Light>& lights);

// The albedo of a plain box (furniture, pillar) standing against walls of albedo about 0.82: a
// few grey levels lighter or darker, the same on all its faces.
double plain_box_albedo(uint64_t seed);

}  // namespace render
}  // namespace hybrid_vo
