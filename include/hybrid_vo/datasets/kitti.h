#pragma once

// The files of the KITTI odometry layout one by one, for read_kitti (readers.h) and the bag
// converter (conversion/kitti_to_bag.h). Errors are "file:line: message" as in text_file.h.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/camera.h"

namespace hybrid_vo {
namespace datasets {

// A rectified camera's 3x4 projection matrix from calib.txt ("P0:", "P1:", ...), its intrinsics
// and where it was read.
struct KittiProjection {
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
  PinholeCamera camera;  // K = P(:, 0:3); width and height unknown (0)
  int line = 0;          // 0 when the matrix is absent
  bool present() const { return line > 0; }
};

struct KittiCalibration {
  KittiProjection P0, P1;  // left and right grayscale cameras
  // The stereo baseline in metres, from P1(0,3) = -fx * b; 0 without P1.
  double baseline() const;
};

// calib.txt: P0 is required, P1 optional (checked only when present); other lines are ignored.
// P1 must have P1(1,3) = P1(2,3) = 0 and a positive baseline.
bool read_kitti_calibration(const std::string& path, KittiCalibration* calibration,
                            std::string* error);

// times.txt: one timestamp (seconds) per line, increasing; trailing blank lines are ignored.
bool read_kitti_times(const std::string& path, std::vector<double>* times, std::string* error);

// poses/<name>.txt: 12 numbers per line, row-major 3x4 [R | c], camera-to-world of cam0.
struct KittiPose {
  Eigen::Matrix3d R_wc = Eigen::Matrix3d::Identity();
  Eigen::Vector3d c_w = Eigen::Vector3d::Zero();
};
bool read_kitti_poses(const std::string& path, std::vector<KittiPose>* poses, std::string* error);

// <sequence_dir>/image_<camera>/<frame as %06d>.png
std::string kitti_image_path(const std::string& sequence_dir, int camera, size_t frame);

// The number of regular files in <sequence_dir>/image_<camera> (-1 when it is not a folder), so
// that callers can check it against times.txt.
int count_kitti_images(const std::string& sequence_dir, int camera);

}  // namespace datasets
}  // namespace hybrid_vo
