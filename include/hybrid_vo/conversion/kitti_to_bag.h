#pragma once

// A KITTI odometry sequence to a bag in our layout (bag_writing.h), the library behind
// hybrid_vo_kitti_to_bag:
//   /camera/left/{image_raw,camera_info}   image_0, K and P from P0 (mono8, rectified: D = 0);
//                                          with --compressed, image_raw/compressed instead
//   /camera/right/{image_raw,camera_info}  with --stereo: image_1, P1 with P(0,3) = -fx * b
//   /tf_static    base_link -> camera_left_optical (and camera_right_optical, b along optical x)
//   /ground_truth/pose, /tf world -> gt_camera_left_optical   when poses exist
// Stamps are start_time + times.txt, so a conversion is deterministic.

#include <string>
#include <vector>

#include "hybrid_vo/conversion/bag_writing.h"

namespace hybrid_vo {
namespace conversion {

struct KittiBagOptions {
  std::string sequence_dir;  // <root>/sequences/<name> with calib.txt, times.txt, image_0/
  std::string poses;         // empty: <root>/poses/<name>.txt when that file exists
  std::string out_bag;
  bool stereo = false;
  // Seconds added to times.txt (which starts at 0): ros::Time 0 is not a valid bag time. 1 s is
  // also where hybrid_vo_render_sequence starts.
  double start_time = 1.0;
  BagImageFormat images;  // raw, or compressed PNG or JPEG (--compressed, --jpeg-quality)
  bool help = false;
};

// Parses the arguments after the program name; an empty string on success, else what is wrong.
std::string parse_kitti_args(const std::vector<std::string>& args, KittiBagOptions* options);
std::string kitti_usage(const std::string& program);

struct KittiBagSummary {
  int frames = 0;
  int width = 0, height = 0;
  std::string poses_path;  // empty: no ground truth written
};

// Converts; false with "file:line: message" (or "file: message") on bad input. OUT.bag appears
// only on success (it is written as OUT.bag.tmp and renamed); a failure leaves no file behind.
bool convert_kitti(const KittiBagOptions& options, std::string* error,
                   KittiBagSummary* summary = nullptr);

}  // namespace conversion
}  // namespace hybrid_vo
