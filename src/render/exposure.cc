// A view integrated over its exposure (motion blur), and how far the image moves meanwhile.

#include <algorithm>
#include <cmath>
#include <limits>

#include "hybrid_vo/render/imaging.h"
#include "hybrid_vo/render/renderer.h"
#include "shading.h"
#include "view_radiance.h"

namespace hybrid_vo {
namespace render {
namespace {

ViewRadiance view_radiance(const Scene& scene, const CameraModel& camera, const CameraPose& pose,
                           const RenderOptions& options, bool with_geometry) {
  if (camera.model == LensModel::kEquidistant)
    return equidistant_radiance(scene, camera, pose, options, with_geometry);
  check(!camera.has_distortion(), "only pinhole and equidistant cameras are rendered");
  return pinhole_radiance(scene, camera.pinhole, pose, options, with_geometry);
}

}  // namespace

RenderedView render_exposure(const Scene& scene, const CameraModel& camera,
                             const std::vector<CameraPose>& poses, const RenderOptions& options) {
  check(poses.size() % 2 == 1, "an exposure needs an odd number of poses (its middle the view's)");
  const size_t middle = poses.size() / 2;
  ViewRadiance view = view_radiance(scene, camera, poses[middle], options, true);
  if (poses.size() > 1) {
    cv::Mat sum;
    view.radiance.convertTo(sum, CV_64F);
    for (size_t k = 0; k < poses.size(); ++k) {
      if (k == middle) continue;
      cv::Mat radiance;
      view_radiance(scene, camera, poses[k], options, false).radiance.convertTo(radiance, CV_64F);
      sum += radiance;
    }
    sum.convertTo(view.radiance, CV_32F, 1.0 / static_cast<double>(poses.size()));
  }
  RenderedView out;
  out.image = sensor_image(view.radiance, options);
  out.depth = view.depth;
  out.quad_id = view.quad_id;
  return out;
}

double image_motion_px(const Scene& scene, const CameraModel& camera, const CameraPose& from,
                       const CameraPose& to) {
  constexpr int kGrid = 9;  // pixels along each axis, corners included
  const PinholeCamera& cam = camera.pinhole;
  double largest = 0.0;
  for (int gy = 0; gy < kGrid; ++gy)
    for (int gx = 0; gx < kGrid; ++gx) {
      const Eigen::Vector2d pixel(gx * (cam.width - 1.0) / (kGrid - 1),
                                  gy * (cam.height - 1.0) / (kGrid - 1));
      const Eigen::Vector3d ray = camera.ray(pixel);
      if (!ray.allFinite()) continue;
      const Eigen::Vector3d direction = to.R_world_from_camera * ray;
      double t = 0.0;
      // Nothing hit: a point far away, which moves with the rotation only.
      const bool hit = cast_ray(scene, to.centre, direction, &t) >= 0;
      const Eigen::Vector3d in_from =
          hit ? from.to_camera(to.centre + t * direction)
              : Eigen::Vector3d(from.R_world_from_camera.transpose() * direction);
      Eigen::Vector2d seen;
      if (!camera.project(in_from, &seen) || !seen.allFinite()) continue;
      largest = std::max(largest, (seen - pixel).norm());
    }
  return largest;
}

}  // namespace render
}  // namespace hybrid_vo
