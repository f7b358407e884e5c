#pragma once

// The options of hybrid_vo_render_pan (a virtual camera panning inside a photograph,
// photo_pan.h and pan_motion.h) and their parsing. The executable reads the files and writes
// the outputs.

#include <string>
#include <vector>

#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/render/imaging.h"
#include "hybrid_vo/render/pan_motion.h"

namespace hybrid_vo {
namespace render {

struct PanOptions {
  std::string photo;
  // The photograph's intrinsics: a Strecha .camera file, or fx, fy, cx, cy given (photo_K, size
  // unknown until the photograph is read); neither: the .camera file found beside the photo.
  std::string camera_file;
  bool has_photo_K = false;
  PinholeCamera photo_K;
  std::string out_bag;  // empty: no bag (then kitti_dir is required)
  std::string kitti_dir;
  std::string kitti_name = "00";
  std::string compression = "lz4";  // none, lz4 or bz2
  int width = 640, height = 480;
  double focal = 1000.0;  // pixels; principal point at the image centre
  double noise = 1.0;     // grey levels: the read noise (constant), 1.5 by --imaging realistic
  ImagingOptions imaging;  // clean by default
  PanMotionOptions motion;
  int drop_every = 0;  // 0: every frame
  bool help = false;
};

// Parses the arguments after the program name. Returns an empty string on success, else a
// message naming the offending argument. --help sets `help` and skips the other checks.
std::string parse_pan_args(const std::vector<std::string>& args, PanOptions* options);
std::string pan_usage(const std::string& program);

// The virtual camera of the options: focal, principal point at the image centre, size.
PinholeCamera pan_camera(const PanOptions& options);

}  // namespace render
}  // namespace hybrid_vo
