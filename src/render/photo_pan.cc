#include "hybrid_vo/render/photo_pan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "hybrid_vo/render/renderer.h"
#include "painter.h"

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

double pan_motion_px(const PinholeCamera& camera, const Eigen::Matrix3d& R_neutral_from_a,
                     const Eigen::Matrix3d& R_neutral_from_b) {
  // A pixel of view b to its pixel in view a.
  const Eigen::Matrix3d H = pan_homography(camera, camera, R_neutral_from_a.transpose() *
                                                               R_neutral_from_b);
  const double x1 = camera.width - 1.0, y1 = camera.height - 1.0;
  double largest = 0.0;
  for (double y : {0.0, 0.5 * y1, y1})
    for (double x : {0.0, 0.5 * x1, x1}) {
      const Eigen::Vector3d p = H * Eigen::Vector3d(x, y, 1.0);
      if (!(p.z() > 0.0)) return std::numeric_limits<double>::infinity();
      largest = std::max(largest, (p.hnormalized() - Eigen::Vector2d(x, y)).norm());
    }
  return largest;
}

PhotoPan::PhotoPan(const cv::Mat& photo, const PinholeCamera& photo_camera,
                   const PinholeCamera& camera, double noise_sigma, uint64_t seed,
                   const ImagingOptions& imaging)
    : photo_camera_(photo_camera),
      camera_(camera),
      noise_sigma_(noise_sigma),
      seed_(seed),
      imaging_(imaging) {
  require(photo_camera.valid() && camera.valid(), "invalid intrinsics");
  require(camera.width >= 1 && camera.height >= 1, "the virtual camera needs a size");
  require(!photo.empty() && photo.type() == CV_8UC1, "the photograph must be 8-bit grey");
  require(photo.cols == photo_camera.width && photo.rows == photo_camera.height,
          "the photograph is " + std::to_string(photo.cols) + "x" + std::to_string(photo.rows) +
              ", its intrinsics are for " + std::to_string(photo_camera.width) + "x" +
              std::to_string(photo_camera.height));
  require(std::isfinite(noise_sigma) && noise_sigma >= 0.0 && noise_sigma <= 100.0,
          "noise must be in [0, 100] grey levels");
  const std::string imaging_error = imaging_problem(imaging);
  require(imaging_error.empty(), imaging_error);
  photo.convertTo(filtered_, CV_32F);
  const double scale = photo_camera.mean_focal() / camera.mean_focal();
  if (scale > 1.0) {
    prefilter_sigma_ = 0.5 * scale;
    cv::GaussianBlur(filtered_, filtered_, cv::Size(0, 0), prefilter_sigma_, prefilter_sigma_,
                     cv::BORDER_REFLECT);
  }
}

cv::Mat PhotoPan::render(const Eigen::Matrix3d& R_photo_from_camera, int frame) const {
  return expose({R_photo_from_camera}, 1.0, frame);
}

std::vector<Eigen::Matrix3d> PhotoPan::exposure_rotations(const PanMotion& motion,
                                                          int frame) const {
  const Eigen::Matrix3d& R = motion.R_neutral_from_camera.at(frame);
  if (!(imaging_.exposure_ms > 0.0)) return {R};
  const double exposure = 1e-3 * imaging_.exposure_ms, time = motion.times.at(frame);
  auto rotation_at = [&](double offset) {
    return offset == 0.0 ? R : motion.R_neutral_from_camera_at(time + offset);
  };
  const double moved = pan_motion_px(camera_, rotation_at(-0.5 * exposure),
                                     rotation_at(0.5 * exposure));
  std::vector<Eigen::Matrix3d> rotations;
  for (double offset :
       exposure_offsets(exposure, exposure_samples(moved, imaging_.max_exposure_samples)))
    rotations.push_back(rotation_at(offset));
  return rotations;
}

cv::Mat PhotoPan::render_frame(const PanMotion& motion, int frame) const {
  return expose(exposure_rotations(motion, frame),
                exposure_gain(imaging_.exposure_drift, seed_, motion.times.at(frame)), frame);
}

cv::Mat PhotoPan::expose(const std::vector<Eigen::Matrix3d>& rotations, double gain,
                         int frame) const {
  cv::Mat radiance;
  for (const Eigen::Matrix3d& R : rotations) {
    const Eigen::Matrix3d h = pan_homography(photo_camera_, camera_, R);
    const cv::Matx33d H(h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2), h(2, 0), h(2, 1),
                        h(2, 2));
    // OpenCV interpolates at 1/32 of a photograph pixel, about 0.01 virtual pixel here: far
    // below the noise.
    cv::Mat view;
    cv::warpPerspective(filtered_, view, H, cv::Size(camera_.width, camera_.height),
                        cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
    if (radiance.empty())
      radiance = view;
    else
      radiance += view;
  }
  if (rotations.size() > 1 || gain != 1.0)
    radiance.convertTo(radiance, CV_32F, gain / static_cast<double>(rotations.size()));
  RenderOptions sensor;
  sensor.blur_sigma = 0.0;  // the prefilter stands in for the optics
  sensor.noise_sigma = noise_sigma_;
  sensor.noise_seed = hash_mix(seed_, static_cast<uint64_t>(frame));
  sensor.vignetting = imaging_.vignetting;
  sensor.shot_noise_gain = imaging_.shot_noise_gain;
  sensor.jpeg_quality = imaging_.jpeg_quality;
  return sensor_image(radiance, sensor);
}

}  // namespace render
}  // namespace hybrid_vo
