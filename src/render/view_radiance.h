#pragma once

// A view before the sensor (imaging.h's sensor_image), as the renderer's cameras make it:
// render_view finishes one, render_exposure averages several first.

#include <opencv2/core.hpp>

#include "hybrid_vo/features/camera_model.h"
#include "hybrid_vo/render/renderer.h"

namespace hybrid_vo {
namespace render {

// The radiance (CV_32FC1, grey levels, exposure applied) and, when asked for, the depth and quad
// ids of render_view.
struct ViewRadiance {
  cv::Mat radiance, depth, quad_id;
};

// Of a pinhole camera (renderer.cc); throws as render_view.
ViewRadiance pinhole_radiance(const Scene& scene, const PinholeCamera& camera,
                              const CameraPose& pose, const RenderOptions& options,
                              bool with_geometry);

// Of an equidistant (fisheye) camera (fisheye_view.cc): every sample's ray is cast through the
// lens model (features/camera_model.h), also beyond 90 degrees off the axis, and shaded as the
// pinhole view's are; depth is the surface's camera z (negative behind the image plane), quad_id
// -1 where a ray meets nothing or the lens has none.
ViewRadiance equidistant_radiance(const Scene& scene, const CameraModel& camera,
                                  const CameraPose& pose, const RenderOptions& options,
                                  bool with_geometry);

}  // namespace render
}  // namespace hybrid_vo
