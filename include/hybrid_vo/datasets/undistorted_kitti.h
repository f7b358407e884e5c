#pragma once

// A sequence of any format that readers.h reads, written in the KITTI odometry layout
// (kitti_writer.h) with its images undistorted: the layout every odometry tool here takes
// (hybrid_vo_bench_frontend, hybrid_vo_kitti_to_bag, scripts/eval_kitti), for data sets such as
// TUM fr1 whose images are distorted and whose poses are a separate, differently stamped file.

#include <string>

#include "hybrid_vo/datasets/sequence.h"

namespace hybrid_vo {
namespace datasets {

struct UndistortedKittiSummary {
  int frames = 0;
  int width = 0, height = 0;
  bool undistorted = false;  // the source's images had a lens model that was removed
};

// Each frame's image, grey, undistorted into the pinhole of its own K (cv::undistort: the same K,
// so pixels far from the centre may fall outside, black), with its time since the first frame and
// its camera-to-world pose. Every frame must share the first one's camera (KITTI's calib.txt has
// one); the equidistant model is refused (it needs a rectified view, fisheye_rectifier.h). False
// with the reason for an empty sequence, such a camera, an unreadable image, or what KittiWriter
// refuses (an existing sequence folder, times that do not increase).
bool write_undistorted_kitti(const Sequence& sequence, const std::string& root,
                             const std::string& name, UndistortedKittiSummary* summary,
                             std::string* error);

}  // namespace datasets
}  // namespace hybrid_vo
