#include "hybrid_vo/geometry/camera.h"

#include <cmath>

namespace hybrid_vo {

bool PinholeCamera::valid() const {
  return std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) && std::isfinite(cy) &&
         fx > 0.0 && fy > 0.0 && width >= 0 && height >= 0;
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d K;
  K << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return K;
}

Eigen::Matrix3d PinholeCamera::K_inverse() const {
  Eigen::Matrix3d Ki;
  Ki << 1.0 / fx, 0.0, -cx / fx, 0.0, 1.0 / fy, -cy / fy, 0.0, 0.0, 1.0;
  return Ki;
}

bool PinholeCamera::in_image(const Eigen::Vector2d& pixel) const {
  if (width <= 0 || height <= 0) return true;
  return pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() <= width - 1.0 &&
         pixel.y() <= height - 1.0;
}

}  // namespace hybrid_vo
