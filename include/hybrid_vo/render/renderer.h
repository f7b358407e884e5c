#pragma once

// Ray casting of a render::Scene through a pinhole camera, or an equidistant (fisheye) one, into
// an 8-bit grey image.
//
// Every pixel averages ss x ss rays (box filter) whose hits are found exactly, so geometric
// edges are antialiased; textures are sampled with anisotropic trilinear mip-mapping at each
// ray's footprint, so distant tiles do not alias into fake corners. A slight Gaussian blur
// stands in for the optics and Gaussian noise for the sensor; a realistic camera's vignetting,
// signal-dependent noise, JPEG (imaging.h) and motion blur (render_exposure) are there on demand.
// Pixel centres sit at integer coordinates (OpenCV's and ROS's convention): pixel (x, y) sees the
// ray through K^-1 (x, y, 1).

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/features/camera_model.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/render/camera_path.h"
#include "hybrid_vo/render/scene.h"

namespace hybrid_vo {
namespace render {

struct RenderOptions {
  int supersampling = 3;     // rays per pixel along each axis (1..8)
  double blur_sigma = 0.5;   // pixels; 0: none
  double noise_sigma = 1.0;  // grey levels; 0: none
  uint64_t noise_seed = 1;   // the sequence uses one per frame and camera
  int max_anisotropy = 4;    // texture taps along the footprint's long axis (1..16)
  double exposure = 1.0;     // grey = 255 * exposure * albedo * irradiance, clamped
  double near = 0.05;        // metres; nearer surfaces are not drawn
  // A realistic sensor's (imaging.h); 0: none, the clean renders'.
  double vignetting = 0.0;       // how much darker the corners are (fraction)
  double shot_noise_gain = 0.0;  // noise variance per grey level of signal, beside noise_sigma^2
  int jpeg_quality = 0;          // 1..100: the image JPEG-coded at this quality
};

struct RenderedView {
  cv::Mat image;    // CV_8UC1
  cv::Mat depth;    // CV_32FC1: camera z of the surface at the pixel centre; 0 where none
  cv::Mat quad_id;  // CV_32SC1: index into scene.quads of that surface; -1 where none
};

// Renders the view of a camera of the given intrinsics (width and height required) at the given
// camera-to-world pose. Deterministic for given inputs. Throws std::invalid_argument for an
// invalid camera or options.
RenderedView render_view(const Scene& scene, const PinholeCamera& camera, const CameraPose& pose,
                         const RenderOptions& options = {});

// The view of a camera with a lens: one without distortion exactly as above; an equidistant
// (fisheye) one by casting every sample's ray through its lens model, also beyond 90 degrees off
// the axis (depth is then the surface's camera z, negative behind the image plane). Other
// distortions are refused (std::invalid_argument), as are lens coefficients that fold back.
RenderedView render_view(const Scene& scene, const CameraModel& camera, const CameraPose& pose,
                         const RenderOptions& options = {});

// The view integrated over an exposure: the radiance of the camera at each of `poses` (the
// exposure's instants, an odd number of them), averaged, then the sensor. The middle pose is the
// view's own: its depth and quad ids are the view's, and one pose is render_view. Throws as
// render_view, and for an even number of poses.
RenderedView render_exposure(const Scene& scene, const CameraModel& camera,
                             const std::vector<CameraPose>& poses, const RenderOptions& options = {});

// How far the image moves, at most, from a camera at `from` to one at `to` (pixels): the scene
// points seen at a grid of pixels from `to` (far away where nothing is hit), projected into
// `from`. What motion blur needs to know to sample an exposure.
double image_motion_px(const Scene& scene, const CameraModel& camera, const CameraPose& from,
                       const CameraPose& to);

// The renderer's fisheye for a width x height image: an equidistant lens whose horizontal field
// of view is fov_deg across the image (to its outer edges), principal point at the centre,
// square pixels, and the coefficients of a real lens (k1..k4 = -0.02, 0.003, -0.0005, 0.0001).
// Throws std::invalid_argument for a field of view outside (0, 220) degrees.
CameraModel fisheye_camera(double fov_deg, int width = 640, int height = 480);

// The nearest quad that the ray origin + t direction hits from its front side (as drawn), at
// t > near: its index, or -1, with t. For a direction of camera z 1, t is the camera depth, the
// exact one that evaluations compare measured depths with (rendered depth maps are at pixel
// centres only).
int cast_ray(const Scene& scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
             double* t, double near = 0.05);

// The renderer's default intrinsics for a width x height image: f = 0.72 * width (a 70-degree
// horizontal field of view), principal point at the centre.
PinholeCamera default_camera(int width = 640, int height = 480);

}  // namespace render
}  // namespace hybrid_vo
