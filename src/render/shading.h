#pragma once

// What the renderer's cameras share (renderer.cc: pinhole, fisheye_view.cc: equidistant): the
// checks of the options and pose, and the shading of a ray's hit on a quad (the sensor that
// finishes the image is imaging.h's sensor_image).

#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hybrid_vo/render/renderer.h"

namespace hybrid_vo {
namespace render {

// Throws std::invalid_argument("render: " + what) unless ok.
void check(bool ok, const std::string& what);
// The options and the pose of a render_view call (throws as check).
void check_render_inputs(const RenderOptions& options, const CameraPose& pose);

// A CV_8UC1 or CV_32FC1 image at (x, y), clamped to the image.
float bilinear(const cv::Mat& m, double x, double y);

// Texture lookup at level-0 texel coordinates (tu, tv), texel c covering [c, c + 1); (du, dv)
// per sample step along the image x and y axes give the footprint.
double sample_texture(const Texture& tex, double tu, double tv, double dux, double dvx, double duy,
                      double dvy, int max_anisotropy);

// Radiance (albedo times irradiance) of quad q at its plane coordinates uv, for a ray whose hit
// moves by dX_dx and dX_dy (world) per sample step along the image x and y axes.
double shade(const Quad& q, const Eigen::Vector2d& uv, const Eigen::Vector3d& dX_dx,
             const Eigen::Vector3d& dX_dy, int max_anisotropy);

// Sample (i, j) of a grid with ss samples per pixel looks through image point
// ((i + 0.5) / ss - 0.5, (j + 0.5) / ss - 0.5).
inline double sample_coord(int i, int ss) { return (i + 0.5) / ss - 0.5; }

// Per-quad constants of the ray-plane test: the plane world[a] = plane, the quad's extent along
// the two other world axes iu, iv, and the bounding box of the samples it may cover.
struct QuadRaster {
  int index = 0;
  int a = 0, iu = 0, iv = 0;
  double plane = 0.0;
  double lo_u = 0.0, hi_u = 0.0, lo_v = 0.0, hi_v = 0.0;
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;  // inclusive, in samples
};

// The plane and extent of quad `index` of `scene` (not its box); false when a camera at `centre`
// is behind it (quads are one-sided: seen from the side their normal points to).
bool quad_plane(const Scene& scene, int index, const Eigen::Vector3d& centre, QuadRaster* r);

}  // namespace render
}  // namespace hybrid_vo
