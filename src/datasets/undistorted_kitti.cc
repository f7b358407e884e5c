#include "hybrid_vo/datasets/undistorted_kitti.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/datasets/kitti_writer.h"

namespace hybrid_vo {
namespace datasets {
namespace {

bool same_camera(const CameraModel& a, const CameraModel& b) {
  return a.model == b.model && a.distortion == b.distortion && a.pinhole.K() == b.pinhole.K();
}

}  // namespace

bool write_undistorted_kitti(const Sequence& sequence, const std::string& root,
                             const std::string& name, UndistortedKittiSummary* summary,
                             std::string* error) {
  *summary = UndistortedKittiSummary();
  if (sequence.frames.empty()) {
    *error = "the sequence has no frames";
    return false;
  }
  const CameraModel& camera = sequence.frames.front().camera;
  if (camera.model == LensModel::kEquidistant) {
    *error = "an equidistant (fisheye) camera: rectify it first, the KITTI layout is a pinhole";
    return false;
  }
  const std::string problem = camera_model_problem(camera);
  if (!problem.empty()) {
    *error = "camera: " + problem;
    return false;
  }
  const cv::Matx33d K(camera.pinhole.fx, 0.0, camera.pinhole.cx, 0.0, camera.pinhole.fy,
                      camera.pinhole.cy, 0.0, 0.0, 1.0);
  const cv::Mat distortion(camera.distortion.size(), 1, CV_64F,
                           const_cast<double*>(camera.distortion.data()));
  KittiWriter writer;
  bool opened = false;
  for (size_t i = 0; i < sequence.frames.size(); ++i) {
    const Frame& frame = sequence.frames[i];
    if (!same_camera(frame.camera, camera)) {
      *error = frame.image_path + ": a camera other than the first frame's";
      return false;
    }
    const cv::Mat image = cv::imread(frame.image_path, cv::IMREAD_GRAYSCALE);
    if (image.empty()) {
      *error = frame.image_path + ": unreadable";
      return false;
    }
    cv::Mat grey;
    if (camera.has_distortion())
      cv::undistort(image, grey, K, distortion, K);
    else
      grey = image;
    if (!opened) {
      PinholeCamera pinhole = camera.pinhole;
      pinhole.width = image.cols;
      pinhole.height = image.rows;
      if (!writer.open(root, name, pinhole, 0.0, error)) return false;
      opened = true;
    }
    const double time = frame.timestamp - sequence.frames.front().timestamp;
    if (!writer.add_frame(time, grey, cv::Mat(), frame.R_wc, frame.c_w, error)) {
      *error = frame.image_path + ": " + *error;
      return false;
    }
    summary->width = image.cols;
    summary->height = image.rows;
  }
  if (!writer.close(error)) return false;
  summary->frames = writer.frames();
  summary->undistorted = camera.has_distortion();
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
