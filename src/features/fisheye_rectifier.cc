#include "hybrid_vo/features/fisheye_rectifier.h"

#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace hybrid_vo {

PinholeCamera FisheyeRectifier::view(int width, int height) const {
  const double f = 0.5 * width / std::tan(0.5 * fov_deg_ * M_PI / 180.0);
  return PinholeCamera(f, f, 0.5 * (width - 1), 0.5 * (height - 1), width, height);
}

bool FisheyeRectifier::same_camera(const CameraModel& fisheye, const Eigen::Matrix3d& R) const {
  const PinholeCamera &a = camera_.pinhole, &b = fisheye.pinhole;
  return have_maps_ && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.width == b.width && a.height == b.height && camera_.distortion == fisheye.distortion &&
         R_ == R;
}

bool FisheyeRectifier::rectify(const CameraModel& fisheye, const Eigen::Matrix3d& R,
                               const cv::Mat& image, cv::Mat* rectified, CameraModel* pinhole,
                               std::string* reason) {
  if (fisheye.model != LensModel::kEquidistant || !fisheye.valid()) {
    *reason = "only a valid equidistant camera is rectified";
    return false;
  }
  if (!(fov_deg_ > 0.0 && fov_deg_ < 180.0)) {
    *reason = "the rectified field of view must be in (0, 180) degrees";
    return false;
  }
  const int width = fisheye.pinhole.width, height = fisheye.pinhole.height;
  if (image.empty() || image.cols != width || image.rows != height) {
    *reason = "the image is not the camera's size";
    return false;
  }
  const PinholeCamera out = view(width, height);
  if (!same_camera(fisheye, R)) {
    const PinholeCamera& p = fisheye.pinhole;
    const cv::Matx33d K(p.fx, 0, p.cx, 0, p.fy, p.cy, 0, 0, 1);
    const cv::Matx33d K_out(out.fx, 0, out.cx, 0, out.fy, out.cy, 0, 0, 1);
    const cv::Vec4d D(fisheye.distortion[0], fisheye.distortion[1], fisheye.distortion[2],
                      fisheye.distortion[3]);
    cv::Matx33d rotation;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) rotation(r, c) = R(r, c);
    // Fixed-point maps: remap's fastest path.
    cv::fisheye::initUndistortRectifyMap(K, D, rotation, K_out, cv::Size(width, height), CV_16SC2,
                                         map1_, map2_);
    camera_ = fisheye;
    R_ = R;
    have_maps_ = true;
    ++maps_built_;
  }
  cv::remap(image, *rectified, map1_, map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  pinhole->pinhole = out;
  pinhole->model = LensModel::kRadialTangential;
  pinhole->distortion = {0, 0, 0, 0, 0};
  return true;
}

}  // namespace hybrid_vo
