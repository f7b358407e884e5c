#pragma once

// The renderer's equidistant (fisheye) camera: render_view for a CameraModel with that lens.

#include "hybrid_vo/frontend/camera_model.h"
#include "hybrid_vo/render/renderer.h"

namespace hybrid_vo {
namespace render {

// Every sample's ray is cast through the lens model (frontend/camera_model.h), also beyond 90
// degrees off the axis, and shaded as the pinhole view's are; depth is the surface's camera z
// (negative behind the image plane), quad_id -1 where a ray meets nothing or the lens has none.
RenderedView render_equidistant_view(const Scene& scene, const CameraModel& camera,
                                     const CameraPose& pose, const RenderOptions& options);

}  // namespace render
}  // namespace hybrid_vo
