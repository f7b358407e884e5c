#pragma once

#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hybrid_vo/features/camera_model.h"

namespace hybrid_vo {

// A strong fisheye's image rectified into a pinhole view, so that straight lines stay straight
// and the segment detectors see them whole: the view has the fisheye image's size, square
// pixels, its principal point at the centre and the stated horizontal field of view. The remap
// tables (cv::fisheye::initUndistortRectifyMap) are built for the first image and kept until the
// camera (intrinsics, coefficients, size or rectifying rotation) changes, so a stream pays for
// them once.
class FisheyeRectifier {
 public:
  explicit FisheyeRectifier(double fov_deg = 100.0) : fov_deg_(fov_deg) {}

  double fov_deg() const { return fov_deg_; }
  // The pinhole camera of the view of a width x height image.
  PinholeCamera view(int width, int height) const;
  // Rectifies an 8-bit image of the equidistant camera `fisheye`, turned by R (camera_info's
  // rectifying rotation: identity for a single camera, the stereo rectification for a pair).
  // *pinhole is the view's camera, without distortion. False with the reason for a camera that
  // is not equidistant or not valid, an image of another size, or a field of view outside
  // (0, 180) degrees.
  bool rectify(const CameraModel& fisheye, const Eigen::Matrix3d& R, const cv::Mat& image,
               cv::Mat* rectified, CameraModel* pinhole, std::string* reason);
  int maps_built() const { return maps_built_; }

 private:
  bool same_camera(const CameraModel& fisheye, const Eigen::Matrix3d& R) const;

  double fov_deg_;
  bool have_maps_ = false;
  CameraModel camera_;
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  cv::Mat map1_, map2_;
  int maps_built_ = 0;
};

}  // namespace hybrid_vo
