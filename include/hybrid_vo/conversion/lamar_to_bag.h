#pragma once

// A LaMAR Capture session (datasets/lamar.h) to a bag in our layout (bag_writing.h), the library
// behind hybrid_vo_lamar_to_bag. Per selected camera stream <name> (the sensor id made a valid
// ROS name, see sanitize_name; a phone's per-frame cameras form one stream):
//   /camera/<name>/image_raw     mono8 (colour images are converted to grey); with --compressed,
//                                image_raw/compressed instead
//   /camera/<name>/camera_info   that image's own camera: K with the principal point moved to
//                                ROS's pixel convention, D per model (OPENCV: plumb_bob
//                                [k1 k2 p1 p2 0]), R = I, P = [K | 0]
// For the first selected stream (the one the node and the launch file use):
//   /tf_static     base_link -> camera_<name>_optical (z forward along base x), plus the other
//                  streams of the same rig through the rig's transforms
//   /ground_truth/pose, /tf world -> gt_camera_<name>_optical: camera-to-world, i.e. the rig's
//                  pose composed with the camera-to-rig transform, at every image with a pose
// Stamps are the microsecond timestamps plus an offset, so a conversion is deterministic.
// Phone images are passed through as stored: upright, with the per-frame intrinsics they were
// stored with (an orientation change mid-session changes the image size).

#include <string>
#include <vector>

#include "hybrid_vo/conversion/bag_writing.h"

namespace hybrid_vo {
namespace conversion {

struct LamarBagOptions {
  std::string session_dir;           // sessions/<id>
  std::string out_bag;
  std::vector<std::string> cameras;  // stream ids (sensor ids, or a per-frame prefix); empty: all
  // Seconds added to every stamp; < 0: 1 s when the first image's timestamp is below 1 s (a
  // 0-based session; ros::Time 0 is not a valid bag time), else 0.
  double time_offset = -1.0;
  BagImageFormat images;  // raw, or compressed PNG or JPEG (--compressed, --jpeg-quality)
  bool help = false;
};

std::string parse_lamar_args(const std::vector<std::string>& args, LamarBagOptions* options);
std::string lamar_usage(const std::string& program);

struct LamarBagSummary {
  std::vector<std::string> streams;  // selected stream ids, first one first
  std::vector<std::string> topics;   // their /camera/<name> prefixes
  std::vector<int> images;           // per stream
  int ground_truth = 0;              // poses written for the first stream
  std::string poses_path;            // where they came from
  double time_offset = 0.0;
};

// Converts; false with "file:line: message" on bad input. OUT.bag appears only on success.
bool convert_lamar(const LamarBagOptions& options, std::string* error,
                   LamarBagSummary* summary = nullptr);

}  // namespace conversion
}  // namespace hybrid_vo
