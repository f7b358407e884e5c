#include "hybrid_vo/render/photo_pan.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "hybrid_vo/render/renderer.h"
#include "painter.h"
#include "shading.h"

namespace hybrid_vo {
namespace render {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("photo pan: " + what);
}

}  // namespace

Eigen::Matrix3d pan_homography(const PinholeCamera& photo, const PinholeCamera& camera,
                               const Eigen::Matrix3d& R_photo_from_camera) {
  return photo.K() * R_photo_from_camera * camera.K_inverse();
}

bool view_inside_photo(const Eigen::Matrix3d& H, const PinholeCamera& camera,
                       const PinholeCamera& photo, double margin, Eigen::Vector2d* outside) {
  const double x1 = camera.width - 1, y1 = camera.height - 1;
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(x1, 0),
                                        Eigen::Vector2d(x1, y1), Eigen::Vector2d(0, y1)}) {
    const Eigen::Vector3d p = H * corner.homogeneous();
    const bool in_front = p.z() > 0.0;
    const Eigen::Vector2d q =
        in_front ? Eigen::Vector2d(p.hnormalized())
                 : Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    if (!in_front || !(q.x() >= margin && q.y() >= margin && q.x() <= photo.width - 1 - margin &&
                       q.y() <= photo.height - 1 - margin)) {
      if (outside) *outside = q;
      return false;
    }
  }
  return true;
}

PhotoPan::PhotoPan(const cv::Mat& photo, const PinholeCamera& photo_camera,
                   const PinholeCamera& camera, double noise_sigma, uint64_t seed)
    : photo_camera_(photo_camera), camera_(camera), noise_sigma_(noise_sigma), seed_(seed) {
  require(photo_camera.valid() && camera.valid(), "invalid intrinsics");
  require(camera.width >= 1 && camera.height >= 1, "the virtual camera needs a size");
  require(!photo.empty() && photo.type() == CV_8UC1, "the photograph must be 8-bit grey");
  require(photo.cols == photo_camera.width && photo.rows == photo_camera.height,
          "the photograph is " + std::to_string(photo.cols) + "x" + std::to_string(photo.rows) +
              ", its intrinsics are for " + std::to_string(photo_camera.width) + "x" +
              std::to_string(photo_camera.height));
  require(std::isfinite(noise_sigma) && noise_sigma >= 0.0 && noise_sigma <= 100.0,
          "noise must be in [0, 100] grey levels");
  photo.convertTo(filtered_, CV_32F);
  const double scale = photo_camera.mean_focal() / camera.mean_focal();
  if (scale > 1.0) {
    prefilter_sigma_ = 0.5 * scale;
    cv::GaussianBlur(filtered_, filtered_, cv::Size(0, 0), prefilter_sigma_, prefilter_sigma_,
                     cv::BORDER_REFLECT);
  }
}

cv::Mat PhotoPan::render(const Eigen::Matrix3d& R_photo_from_camera, int frame) const {
  const Eigen::Matrix3d h = pan_homography(photo_camera_, camera_, R_photo_from_camera);
  const cv::Matx33d H(h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2), h(2, 0), h(2, 1),
                      h(2, 2));
  // OpenCV interpolates at 1/32 of a photograph pixel, about 0.01 virtual pixel here: far
  // below the noise.
  cv::Mat radiance;
  cv::warpPerspective(filtered_, radiance, H, cv::Size(camera_.width, camera_.height),
                      cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
  RenderOptions sensor;
  sensor.blur_sigma = 0.0;  // the prefilter stands in for the optics
  sensor.noise_sigma = noise_sigma_;
  sensor.noise_seed = hash_mix(seed_, static_cast<uint64_t>(frame));
  return finish(radiance, sensor);
}

}  // namespace render
}  // namespace hybrid_vo
