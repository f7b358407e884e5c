#pragma once

// A virtual pinhole camera turning about its own centre inside a large photograph: it sees the
// photograph through the homography H = K_photo R K_camera^-1 (a virtual pixel to a photograph
// pixel; R turns the virtual camera's frame into the photograph camera's), exact for any depth
// of the scene because the centre does not move. So a real photograph gives a real-looking
// rotation-only sequence with a perfect ground truth. Pixel centres sit at integer coordinates.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/render/imaging.h"
#include "hybrid_vo/render/pan_motion.h"

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

// How far the image of `camera` moves, at most, when it turns about its centre from
// R_neutral_from_a to R_neutral_from_b (pixels; corners, edge middles and centre).
double pan_motion_px(const PinholeCamera& camera, const Eigen::Matrix3d& R_neutral_from_a,
                     const Eigen::Matrix3d& R_neutral_from_b);

class PhotoPan {
 public:
  // photo: 8-bit grey, of photo_camera's width x height. When the virtual camera's focal length
  // is smaller, each of its pixels covers `scale` = f_photo / f_camera photograph pixels: the
  // photograph is blurred once by a Gaussian of sigma 0.5 scale (the renderer's 0.5-pixel optics
  // blur, in photograph pixels), which also keeps the downscale from aliasing; the footprint
  // varies little across a view of a few tens of degrees, so one isotropic filter serves every
  // frame. `imaging` (imaging.h) makes the camera a realistic one. Throws
  // std::invalid_argument for an invalid camera, noise, imaging or photo.
  PhotoPan(const cv::Mat& photo, const PinholeCamera& photo_camera, const PinholeCamera& camera,
           double noise_sigma, uint64_t seed, const ImagingOptions& imaging = {});

  // The virtual camera's 8-bit grey view at one instant: bilinear through pan_homography, then
  // the sensor (sensor_image): noise of noise_sigma grey levels seeded by the seed and the frame,
  // and the imaging's vignetting, shot noise and JPEG.
  cv::Mat render(const Eigen::Matrix3d& R_photo_from_camera, int frame) const;

  // A frame of `motion` (its neutral orientation the photograph camera's) over its exposure: the
  // views at exposure_rotations averaged, at the auto exposure's gain of the frame's time, then
  // the sensor. Without an exposure or drift, render(R_neutral_from_camera[frame], frame).
  cv::Mat render_frame(const PanMotion& motion, int frame) const;
  // The rotations over the frame's exposure, centred on its time: as many (odd) as keep
  // consecutive views within a pixel, up to the imaging's limit; the middle one the frame's.
  std::vector<Eigen::Matrix3d> exposure_rotations(const PanMotion& motion, int frame) const;

  double prefilter_sigma() const { return prefilter_sigma_; }
  const PinholeCamera& photo_camera() const { return photo_camera_; }
  const PinholeCamera& camera() const { return camera_; }

 private:
  cv::Mat filtered_;  // CV_32FC1
  PinholeCamera photo_camera_, camera_;
  // The views at the rotations averaged, times the gain, through the sensor.
  cv::Mat expose(const std::vector<Eigen::Matrix3d>& R_photo_from_camera, double gain,
                 int frame) const;

  double noise_sigma_ = 0.0, prefilter_sigma_ = 0.0;
  uint64_t seed_ = 1;
  ImagingOptions imaging_;
};

}  // namespace render
}  // namespace hybrid_vo
