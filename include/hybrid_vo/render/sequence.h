#pragma once

// A rendered sequence without ROS: the options of hybrid_vo_render_sequence and their parsing,
// the scene, trajectory and camera they define, and per-frame rendering. The executable adds
// the bag writing.

#include <cstdint>
#include <string>
#include <vector>

#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/render/camera_path.h"
#include "hybrid_vo/render/imaging.h"
#include "hybrid_vo/render/renderer.h"
#include "hybrid_vo/render/scene.h"

namespace hybrid_vo {
namespace render {

struct SequenceOptions {
  std::string out_bag;  // empty: no bag (then kitti_dir is required)
  std::string png_dir;  // empty: no PNGs
  // Not empty: also the KITTI odometry layout (datasets/kitti_writer.h), as
  // <kitti_dir>/sequences/<kitti_name>/ and <kitti_dir>/poses/<kitti_name>.txt.
  std::string kitti_dir;
  std::string kitti_name = "00";
  int frames = 150;
  // > 0: the frame count is this many laps of the scene's closed route at `speed` and `rate`
  // (rounded), replacing `frames`; one lap replayed in a loop makes an endless walk.
  double laps = 0.0;
  bool stereo = false;
  int width = 640, height = 480;
  double rate = 10.0;  // Hz
  uint64_t seed = 1;   // scene, sway and noise
  SceneType scene = SceneType::kCorridor;
  TextureStyle texture = TextureStyle::kTextured;
  double baseline = 0.12;  // metres, stereo only
  double speed = 1.5;      // metres per second
  // How the camera moves (camera_path.h); the turn's and the ramp's options below apply to
  // those motions only.
  Motion motion = Motion::kWalk;
  double lever_arm = 0.2;     // turn: metres from the camera centre back to the vertical axis
  double turn_rate = 30.0;    // turn: deg/s (positive: left), reached after a 1 s ramp
  bool turn_stop = false;     // turn: ramp down to rest over the last second
  double rest_seconds = 1.0;  // ramp: still at first
  double ramp_seconds = 2.0;  // ramp: then accelerating to `speed`
  double focal = 0.0;      // pixels; 0: 0.72 * width
  // > 0: an equidistant (fisheye) lens of this horizontal field of view in degrees
  // (fisheye_camera), instead of the pinhole.
  double fisheye_fov = 0.0;
  double noise = 1.0;      // grey levels: the read noise (constant), 1.5 by --imaging realistic
  ImagingOptions imaging;  // clean by default
  int supersampling = 3;
  std::string compression = "lz4";  // none, lz4 or bz2
  std::string compressed_images;    // empty: raw images; png or jpeg: CompressedImage topics
  int jpeg_quality = 95;
  bool help = false;
};

// Parses the arguments after the program name. Returns an empty string on success, else a
// message naming the offending argument. --help sets `help` and skips the other checks.
std::string parse_sequence_args(const std::vector<std::string>& args, SequenceOptions* options);
std::string sequence_usage(const std::string& program);

// An empty string when `path` can be created as a file (its directory exists and is
// writable), else why not.
std::string check_writable_file(const std::string& path);

// Frame i's stamp in nanoseconds: 1 s + i / rate, exactly (integer arithmetic).
uint64_t frame_stamp_ns(int i, double rate);

struct Sequence {
  SequenceOptions options;
  Scene scene;
  Trajectory trajectory;
  PinholeCamera camera;  // both cameras of a stereo pair: K (of the fisheye too)
  CameraModel lens;      // camera without distortion, or the fisheye
  RenderOptions render;
};

// Builds the scene and trajectory. Throws std::invalid_argument for invalid options.
Sequence make_sequence(const SequenceOptions& options);

// Renders frame i of the left camera, or of the right one (stereo: centre shifted by the
// baseline along the left camera's x axis). The noise differs per frame and camera. With an
// exposure (options.imaging), the views along the path over the exposure are averaged, as many
// as keep consecutive ones within a pixel: the frame's pose, its ground truth, is the middle of
// the exposure.
RenderedView render_frame(const Sequence& sequence, int frame, bool right = false);
// The camera's poses that frame i integrates over (odd in number, the middle one frame_pose).
std::vector<CameraPose> exposure_poses(const Sequence& sequence, int frame, bool right = false);
CameraPose frame_pose(const Sequence& sequence, int frame, bool right = false);

}  // namespace render
}  // namespace hybrid_vo
