#pragma once

// A virtual pinhole camera turning about its own centre inside a large photograph: it sees the
// photograph through the homography H = K_photo R K_camera^-1 (a virtual pixel to a photograph
// pixel; R turns the virtual camera's frame into the photograph camera's), exact for any depth
// of the scene because the centre does not move. So a real photograph gives a real-looking
// rotation-only sequence with a perfect ground truth. Pixel centres sit at integer coordinates.

#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hybrid_vo/geometry/camera.h"

namespace hybrid_vo {
namespace render {

Eigen::Matrix3d pan_homography(const PinholeCamera& photo, const PinholeCamera& camera,
                               const Eigen::Matrix3d& R_photo_from_camera);

// Whether every pixel of `camera` (its width x height) lands at least `margin` pixels inside the
// photograph (photo.width x photo.height) through H. A rectangle's image under a homography is
// the quadrilateral of its corners' images when all lie in front, so the corners decide; on
// false, *outside (when given) is the first corner's image that does not (NaN when behind).
bool view_inside_photo(const Eigen::Matrix3d& H, const PinholeCamera& camera,
                       const PinholeCamera& photo, double margin,
                       Eigen::Vector2d* outside = nullptr);

class PhotoPan {
 public:
  // photo: 8-bit grey, of photo_camera's width x height. When the virtual camera's focal length
  // is smaller, each of its pixels covers `scale` = f_photo / f_camera photograph pixels: the
  // photograph is blurred once by a Gaussian of sigma 0.5 scale (the renderer's 0.5-pixel optics
  // blur, in photograph pixels), which also keeps the downscale from aliasing; the footprint
  // varies little across a view of a few tens of degrees, so one isotropic filter serves every
  // frame. Throws std::invalid_argument for an invalid camera, noise or photo.
  PhotoPan(const cv::Mat& photo, const PinholeCamera& photo_camera, const PinholeCamera& camera,
           double noise_sigma, uint64_t seed);

  // The virtual camera's 8-bit grey view: bilinear through pan_homography, then Gaussian noise
  // of noise_sigma grey levels, seeded by the seed and the frame.
  cv::Mat render(const Eigen::Matrix3d& R_photo_from_camera, int frame) const;

  double prefilter_sigma() const { return prefilter_sigma_; }
  const PinholeCamera& photo_camera() const { return photo_camera_; }
  const PinholeCamera& camera() const { return camera_; }

 private:
  cv::Mat filtered_;  // CV_32FC1
  PinholeCamera photo_camera_, camera_;
  double noise_sigma_ = 0.0, prefilter_sigma_ = 0.0;
  uint64_t seed_ = 1;
};

}  // namespace render
}  // namespace hybrid_vo
