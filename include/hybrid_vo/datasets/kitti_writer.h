#pragma once

// Writes a sequence in the KITTI odometry layout that read_kitti (readers.h), the KITTI file
// readers (kitti.h), hybrid_vo_kitti_to_bag and hybrid_vo_bench_frontend read:
//   <root>/sequences/<name>/image_0/%06d.png   the left (or only) camera, 8-bit grey
//   <root>/sequences/<name>/image_1/%06d.png   the right camera of a rectified stereo pair
//   <root>/sequences/<name>/calib.txt          P0 = K [I | 0]; stereo also P1 = K [I | (-b, 0, 0)]
//                                               (P1(0,3) = -fx b), as KITTI writes it
//   <root>/sequences/<name>/times.txt          seconds, one line per frame
//   <root>/poses/<name>.txt                    row-major 3x4 camera-to-world [R | c] of the left
//                                               camera, one line per frame
// Poses are in the caller's world frame (KITTI's own start at the identity; nothing here needs
// that).

#include <fstream>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hybrid_vo/geometry/camera.h"

namespace hybrid_vo {
namespace datasets {

class KittiWriter {
 public:
  // Creates the folders and writes calib.txt; baseline 0 is a mono sequence (P0 only), a
  // positive one stereo. False with the reason for an invalid camera or baseline, a name that is
  // not one folder, a sequence folder or poses file that already exists (an older sequence's
  // frames would mix with these), or a root that cannot be written.
  bool open(const std::string& root, const std::string& name, const PinholeCamera& camera,
            double baseline, std::string* error);

  // Appends the next frame: its time (increasing), its images (right: stereo only) and the left
  // camera's camera-to-world pose. False with the reason for a time that does not increase,
  // images that are not 8-bit grey of the first frame's size, a missing right image in stereo, a
  // pose that is not finite, or a failed write.
  bool add_frame(double time, const cv::Mat& left, const cv::Mat& right,
                 const Eigen::Matrix3d& R_world_from_camera, const Eigen::Vector3d& centre,
                 std::string* error);

  // Flushes times.txt and the poses; false when a write failed or no frame was added.
  bool close(std::string* error);

  std::string sequence_dir() const { return sequence_dir_; }
  std::string poses_path() const { return poses_path_; }
  int frames() const { return frames_; }

 private:
  std::string sequence_dir_, poses_path_;
  bool stereo_ = false;
  int frames_ = 0;
  double last_time_ = 0.0;
  cv::Size size_;
  std::ofstream times_, poses_;
};

}  // namespace datasets
}  // namespace hybrid_vo
