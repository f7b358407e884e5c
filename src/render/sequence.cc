#include "hybrid_vo/render/sequence.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "imaging_arguments.h"
#include "number_arguments.h"
#include "painter.h"

namespace hybrid_vo {
namespace render {

std::string sequence_usage(const std::string& program) {
  std::ostringstream s;
  s << "Usage: " << program << " --out OUT.bag | --kitti-dir DIR [options]\n"
    << "Renders a synthetic Manhattan sequence (textured corridor or room, a walk with turns,\n"
    << "or standing, turning in place, starting from rest: --motion)\n"
    << "into a bag: /camera/left/{image_raw,camera_info} (and /camera/right/... with --stereo),\n"
    << "/ground_truth/pose, /tf (world -> gt_camera_left_optical) and /tf_static; and/or into\n"
    << "the KITTI odometry layout.\n"
    << "  --frames N         frames (default 150)\n"
    << "  --laps L           instead of --frames: L laps of the closed route (e.g. 1 for a loop)\n"
    << "  --stereo           also render the right camera\n"
    << "  --width W --height H  image size (default 640 x 480)\n"
    << "  --rate HZ          frame rate (default 10)\n"
    << "  --seed S           scene, walk and noise seed (default 1)\n"
    << "  --scene corridor|room  (default corridor)\n"
    << "  --texture textured|plain  surfaces: posters, doors, tiles (default), or plain\n"
    << "                     (low texture: only the edges of walls, boxes, doors, floor joints)\n"
    << "  --baseline M       stereo baseline in metres (default 0.12)\n"
    << "  --speed M_PER_S    walking speed (default 1.5)\n"
    << "  --motion walk|rest|turn|ramp|handheld  how the camera moves (default walk): walk\n"
    << "                     along the route; rest: stand still at its start (only the noise\n"
    << "                     changes); turn: turn in place there like a wheeled robot; ramp:\n"
    << "                     rest, then start walking; handheld: a hand-held camera strolling\n"
    << "                     along the route (--speed default 0.09) and looking around, shaking\n"
    << "  --lever-arm M      turn: the vertical axis this far behind the camera (default 0.2;\n"
    << "                     0: about the camera centre)\n"
    << "  --turn-rate DEG_S  turn: the yaw rate after a smooth 1 s ramp (default 30; negative:\n"
    << "                     to the right)\n"
    << "  --turn-stop        turn: ramp down to rest over the last second\n"
    << "  --rest-seconds S   ramp: still for S seconds first (default 1)\n"
    << "  --ramp-seconds S   ramp: then accelerating smoothly to --speed over S seconds\n"
    << "                     (default 2); the walker's sway grows with the speed\n"
    << "  --focal PX         focal length (default 0.72 * width)\n"
    << "  --fisheye-fov DEG  an equidistant (fisheye) lens of this horizontal field of view\n"
    << "                     instead of the pinhole (camera_info distortion_model equidistant)\n"
    << "  --supersampling K  K x K rays per pixel (default 3)\n"
    << "  --compression none|lz4|bz2  bag compression (default lz4)\n"
    << "  --compressed png|jpeg  images as sensor_msgs/CompressedImage on .../image_raw/compressed\n"
    << "  --jpeg-quality Q   with --compressed jpeg: quality 1..100 (default 95)\n"
    << imaging_usage()
    << "  --png-dir DIR      also write the images as PNG files\n"
    << "  --kitti-dir DIR    also write DIR/sequences/NAME/{image_0,image_1,calib.txt,times.txt}\n"
    << "                     and DIR/poses/NAME.txt (left camera-to-world in the scene's world)\n"
    << "  --kitti-name NAME  the KITTI sequence name (default 00)\n";
  return s.str();
}

std::string parse_sequence_args(const std::vector<std::string>& args, SequenceOptions* o) {
  std::vector<std::string> motion_options;  // given, to check against the motion at the end
  bool speed_given = false;
  ImagingArguments imaging;
  bool noise_given = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      o->help = true;
      return "";
    }
    if (arg == "--stereo") {
      o->stereo = true;
      continue;
    }
    if (arg == "--turn-stop") {
      o->turn_stop = true;
      motion_options.push_back(arg);
      continue;
    }
    if (is_imaging_option(arg)) {
      if (i + 1 >= args.size()) return arg + " needs a value";
      if (!parse_imaging_option(arg, args[i + 1], &imaging))
        return "bad value '" + args[i + 1] + "' for " + arg;
      ++i;
      continue;
    }
    noise_given = noise_given || arg == "--noise";
    static const char* kValued[] = {"--out",           "--png-dir",    "--frames", "--width",
                                    "--height",        "--rate",       "--seed",   "--scene",
                                    "--baseline",      "--speed",      "--focal",  "--noise",
                                    "--supersampling", "--compression", "--laps",
                                    "--texture",       "--kitti-dir",   "--kitti-name",
                                    "--compressed",    "--jpeg-quality", "--fisheye-fov",
                                    "--motion",        "--lever-arm",    "--turn-rate",
                                    "--rest-seconds",  "--ramp-seconds"};
    bool known = false;
    for (const char* name : kValued) known = known || arg == name;
    if (!known) return "unknown argument '" + arg + "'";
    if (i + 1 >= args.size()) return arg + " needs a value";
    const std::string& v = args[++i];
    bool ok = true;
    if (arg == "--out") {
      o->out_bag = v;
      ok = !v.empty();
    } else if (arg == "--png-dir") {
      o->png_dir = v;
      ok = !v.empty();
    } else if (arg == "--frames") {
      ok = parse_int(v, 1, 100000, &o->frames);
    } else if (arg == "--laps") {
      ok = parse_double(v, 0.0, 100.0, true, &o->laps);
    } else if (arg == "--width") {
      ok = parse_int(v, 16, 4096, &o->width);
    } else if (arg == "--height") {
      ok = parse_int(v, 16, 4096, &o->height);
    } else if (arg == "--rate") {
      ok = parse_double(v, 0.0, 1000.0, true, &o->rate);
    } else if (arg == "--seed") {
      ok = parse_u64(v, &o->seed);
    } else if (arg == "--scene") {
      ok = parse_scene_type(v, &o->scene);
    } else if (arg == "--texture") {
      ok = parse_texture_style(v, &o->texture);
    } else if (arg == "--kitti-dir") {
      o->kitti_dir = v;
      ok = !v.empty();
    } else if (arg == "--kitti-name") {
      o->kitti_name = v;
      ok = !v.empty() && v != "." && v != ".." && v.find('/') == std::string::npos;
    } else if (arg == "--baseline") {
      ok = parse_double(v, 0.0, 2.0, true, &o->baseline);
    } else if (arg == "--speed") {
      ok = parse_double(v, 0.0, 5.0, true, &o->speed);
      speed_given = true;
    } else if (arg == "--focal") {
      ok = parse_double(v, 0.0, 1e5, true, &o->focal);
    } else if (arg == "--noise") {
      ok = parse_double(v, 0.0, 50.0, false, &o->noise);
    } else if (arg == "--supersampling") {
      ok = parse_int(v, 1, 8, &o->supersampling);
    } else if (arg == "--compression") {
      o->compression = v;
      ok = v == "none" || v == "lz4" || v == "bz2";
    } else if (arg == "--compressed") {
      o->compressed_images = v;
      ok = v == "png" || v == "jpeg";
    } else if (arg == "--fisheye-fov") {
      ok = parse_double(v, 0.0, 200.0, true, &o->fisheye_fov);
    } else if (arg == "--jpeg-quality") {
      ok = parse_int(v, 1, 100, &o->jpeg_quality);
    } else if (arg == "--motion") {
      ok = parse_motion(v, &o->motion);
    } else if (arg == "--lever-arm") {
      ok = parse_double(v, 0.0, 2.0, false, &o->lever_arm);
    } else if (arg == "--turn-rate") {
      ok = parse_double(v, -360.0, 360.0, false, &o->turn_rate);
    } else if (arg == "--rest-seconds") {
      ok = parse_double(v, 0.0, 3600.0, false, &o->rest_seconds);
    } else if (arg == "--ramp-seconds") {
      ok = parse_double(v, 0.0, 600.0, false, &o->ramp_seconds);
    }
    if (arg == "--lever-arm" || arg == "--turn-rate" || arg == "--rest-seconds" ||
        arg == "--ramp-seconds")
      motion_options.push_back(arg);
    if (!ok) return "bad value '" + v + "' for " + arg;
  }
  if (o->motion == Motion::kHandheld && !speed_given) o->speed = 0.09;
  o->imaging = resolve_imaging(imaging, noise_given, &o->noise);
  if (o->out_bag.empty() && o->kitti_dir.empty())
    return "--out OUT.bag or --kitti-dir DIR is required";
  if (const std::string problem = imaging_rate_problem(o->imaging, o->rate); !problem.empty())
    return problem;
  if (o->focal > 0.0 && o->fisheye_fov > 0.0)
    return "--focal and --fisheye-fov exclude each other (the field of view sets the focal)";
  if (!o->kitti_dir.empty() && o->fisheye_fov > 0.0)
    return "--kitti-dir writes a pinhole calib.txt: not with --fisheye-fov";
  for (const std::string& option : motion_options) {
    const Motion needs = option == "--rest-seconds" || option == "--ramp-seconds" ? Motion::kRamp
                                                                                 : Motion::kTurn;
    if (o->motion != needs)
      return option + " is an option of --motion " + to_string(needs) + ", not " +
             to_string(o->motion);
  }
  if (o->laps > 0.0 && o->motion != Motion::kWalk)
    return std::string("--laps measures a walk: not with --motion ") + to_string(o->motion);
  return "";
}

std::string check_writable_file(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) return "empty path";
  std::error_code ec;
  const fs::path p(path);
  if (fs::is_directory(p, ec)) return "'" + path + "' is a directory";
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) return "directory '" + dir.string() + "' does not exist";
  if (::access(dir.c_str(), W_OK) != 0) return "directory '" + dir.string() + "' is not writable";
  if (fs::exists(p, ec) && ::access(p.c_str(), W_OK) != 0) return "'" + path + "' is not writable";
  return "";
}

uint64_t frame_stamp_ns(int i, double rate) {
  return 1000000000ull + static_cast<uint64_t>(std::llround(i * (1e9 / rate)));
}

Sequence make_sequence(const SequenceOptions& options) {
  Sequence seq;
  seq.options = options;
  SceneOptions scene;
  scene.type = options.scene;
  scene.texture = options.texture;
  scene.seed = options.seed;
  seq.scene = build_scene(scene);
  if (options.laps > 0.0) {
    const double frames =
        std::round(options.laps * route_length(seq.scene) / options.speed * options.rate);
    if (!(frames >= 2.0 && frames <= 1e6))
      throw std::invalid_argument("render sequence: --laps gives " + std::to_string(frames) +
                                  " frames");
    seq.options.frames = static_cast<int>(frames);
  }
  PathOptions path;
  path.num_frames = seq.options.frames;
  path.rate_hz = options.rate;
  path.speed = options.speed;
  path.seed = options.seed;
  path.motion = options.motion;
  path.lever_arm = options.lever_arm;
  path.turn_rate_deg = options.turn_rate;
  path.turn_stop = options.turn_stop;
  path.rest_seconds = options.rest_seconds;
  path.ramp_seconds = options.ramp_seconds;
  seq.trajectory = make_trajectory(seq.scene, path);
  seq.camera = default_camera(options.width, options.height);
  if (options.focal > 0.0) seq.camera.fx = seq.camera.fy = options.focal;
  seq.lens.pinhole = seq.camera;
  if (options.fisheye_fov > 0.0) {
    seq.lens = fisheye_camera(options.fisheye_fov, options.width, options.height);
    seq.camera = seq.lens.pinhole;
  }
  seq.render.supersampling = options.supersampling;
  seq.render.noise_sigma = options.noise;
  if (const std::string problem = imaging_problem(options.imaging); !problem.empty())
    throw std::invalid_argument("render sequence: " + problem);
  seq.render.vignetting = options.imaging.vignetting;
  seq.render.shot_noise_gain = options.imaging.shot_noise_gain;
  seq.render.jpeg_quality = options.imaging.jpeg_quality;
  if (options.stereo && !(options.baseline > 0.0))
    throw std::invalid_argument("render sequence: the stereo baseline must be positive");
  return seq;
}

CameraPose frame_pose(const Sequence& seq, int frame, bool right) {
  if (frame < 0 || frame >= static_cast<int>(seq.trajectory.poses.size()))
    throw std::out_of_range("render sequence: no frame " + std::to_string(frame));
  const CameraPose& left = seq.trajectory.poses[frame];
  return right ? stereo_right(left, seq.options.baseline) : left;
}

std::vector<CameraPose> exposure_poses(const Sequence& seq, int frame, bool right) {
  const CameraPose pose = frame_pose(seq, frame, right);
  const ImagingOptions& imaging = seq.options.imaging;
  if (!(imaging.exposure_ms > 0.0)) return {pose};
  const double exposure = 1e-3 * imaging.exposure_ms, time = seq.trajectory.times[frame];
  auto pose_at = [&](double offset) {
    if (offset == 0.0) return pose;
    const CameraPose left = seq.trajectory.pose_at(time + offset);
    return right ? stereo_right(left, seq.options.baseline) : left;
  };
  const double motion = image_motion_px(seq.scene, seq.lens, pose_at(-0.5 * exposure),
                                        pose_at(0.5 * exposure));
  std::vector<CameraPose> poses;
  for (double offset :
       exposure_offsets(exposure, exposure_samples(motion, imaging.max_exposure_samples)))
    poses.push_back(pose_at(offset));
  return poses;
}

RenderedView render_frame(const Sequence& seq, int frame, bool right) {
  RenderOptions render = seq.render;
  render.noise_seed =
      hash_mix(seq.options.seed, 2 * static_cast<uint64_t>(frame) + (right ? 1 : 0));
  // One gain for both cameras of the pair, as one auto exposure drives both.
  render.exposure *= exposure_gain(seq.options.imaging.exposure_drift, seq.options.seed,
                                   seq.trajectory.times.at(frame));
  return render_exposure(seq.scene, seq.lens, exposure_poses(seq, frame, right), render);
}

}  // namespace render
}  // namespace hybrid_vo
