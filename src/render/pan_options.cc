#include "hybrid_vo/render/pan_options.h"

#include <sstream>

#include "imaging_arguments.h"
#include "number_arguments.h"

namespace hybrid_vo {
namespace render {
namespace {

// "fx,fy,cx,cy": four finite numbers, positive focal lengths.
bool parse_intrinsics(const std::string& s, PinholeCamera* camera) {
  std::vector<double> v;
  std::stringstream in(s);
  std::string field;
  while (std::getline(in, field, ',')) {
    double x = 0.0;
    if (!parse_double(field, -1e7, 1e7, false, &x)) return false;
    v.push_back(x);
  }
  if (v.size() != 4 || !(v[0] > 0.0) || !(v[1] > 0.0) || s.back() == ',') return false;
  *camera = PinholeCamera(v[0], v[1], v[2], v[3]);
  return true;
}

}  // namespace

std::string pan_usage(const std::string& program) {
  std::ostringstream s;
  s << "Usage: " << program << " --photo PHOTO.jpg (--out OUT.bag | --kitti-dir DIR) [options]\n"
    << "A virtual pinhole camera turning about its own centre inside a photograph: a smooth\n"
    << "random pan (yaw, pitch, roll) whose views are the photograph through a homography, so\n"
    << "that the ground truth (a pure rotation) is exact whatever the scene's depth. Writes the\n"
    << "KITTI odometry layout (poses: camera-to-world, the world being the first frame's\n"
    << "camera) and/or a bag as hybrid_vo_render_sequence writes it (mono, /camera/left).\n"
    << "  --photo FILE       the photograph (read as 8-bit grey)\n"
    << "  --camera FILE      its intrinsics, a Strecha .camera file (26 numbers: K, distortion\n"
    << "                     0 0 0, R, C, width height); default: FILE.camera in the sibling\n"
    << "                     gt_dense_cameras/ folder (the Strecha layout), or beside the photo\n"
    << "  --K fx,fy,cx,cy    its intrinsics instead, in pixels\n"
    << "  --out OUT.bag      the bag\n"
    << "  --kitti-dir DIR    DIR/sequences/NAME/{image_0,calib.txt,times.txt}, DIR/poses/NAME.txt\n"
    << "  --kitti-name NAME  the KITTI sequence name (default 00)\n"
    << "  --width W --height H  the virtual image (default 640 x 480)\n"
    << "  --focal PX         its focal length (default 1000; principal point at the centre)\n"
    << "  --frames N         frames (default 300)\n"
    << "  --rate HZ          frame rate (default 30)\n"
    << "  --seed S           the pan's and the noise's seed (default 1)\n"
    << "  --yaw-deg A        the pan stays within +-A degrees of yaw (default 8), and reaches it\n"
    << "  --pitch-deg A      ... of pitch (default 3)\n"
    << "  --roll-deg A       ... of roll (default 2)\n"
    << "  --max-step-deg D   the fastest turn between two frames (default 1.3); the pan's speed\n"
    << "                     is set so that it reaches it, and slows down where it reverses\n"
    << "  --drop-every N     leave out every N-th frame (N >= 2), as a busy machine drops them\n"
    << "                     (default 0: none); the others keep their true stamps\n"
    << imaging_usage()
    << "  --compression none|lz4|bz2  bag compression (default lz4)\n";
  return s.str();
}

std::string parse_pan_args(const std::vector<std::string>& args, PanOptions* o) {
  ImagingArguments imaging;
  bool noise_given = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      o->help = true;
      return "";
    }
    if (is_imaging_option(arg)) {
      if (i + 1 >= args.size()) return arg + " needs a value";
      if (!parse_imaging_option(arg, args[i + 1], &imaging))
        return "bad value '" + args[i + 1] + "' for " + arg;
      ++i;
      continue;
    }
    noise_given = noise_given || arg == "--noise";
    static const char* kValued[] = {
        "--photo",        "--camera",     "--K",       "--out",        "--kitti-dir",
        "--kitti-name",   "--width",      "--height",  "--focal",      "--frames",
        "--rate",         "--seed",       "--yaw-deg", "--pitch-deg",  "--roll-deg",
        "--max-step-deg", "--drop-every", "--noise",   "--compression"};
    bool known = false;
    for (const char* name : kValued) known = known || arg == name;
    if (!known) return "unknown argument '" + arg + "'";
    if (i + 1 >= args.size()) return arg + " needs a value";
    const std::string& v = args[++i];
    bool ok = true;
    PanMotionOptions& m = o->motion;
    if (arg == "--photo") {
      o->photo = v;
      ok = !v.empty();
    } else if (arg == "--camera") {
      o->camera_file = v;
      ok = !v.empty();
    } else if (arg == "--K") {
      ok = parse_intrinsics(v, &o->photo_K);
      o->has_photo_K = ok;
    } else if (arg == "--out") {
      o->out_bag = v;
      ok = !v.empty();
    } else if (arg == "--kitti-dir") {
      o->kitti_dir = v;
      ok = !v.empty();
    } else if (arg == "--kitti-name") {
      o->kitti_name = v;
      ok = !v.empty() && v != "." && v != ".." && v.find('/') == std::string::npos;
    } else if (arg == "--width") {
      ok = parse_int(v, 16, 4096, &o->width);
    } else if (arg == "--height") {
      ok = parse_int(v, 16, 4096, &o->height);
    } else if (arg == "--focal") {
      ok = parse_double(v, 0.0, 1e5, true, &o->focal);
    } else if (arg == "--frames") {
      ok = parse_int(v, 2, 100000, &m.frames);
    } else if (arg == "--rate") {
      ok = parse_double(v, 0.0, 1000.0, true, &m.rate);
    } else if (arg == "--seed") {
      ok = parse_u64(v, &m.seed);
    } else if (arg == "--yaw-deg") {
      ok = parse_double(v, 0.0, 45.0, false, &m.yaw_deg);
    } else if (arg == "--pitch-deg") {
      ok = parse_double(v, 0.0, 45.0, false, &m.pitch_deg);
    } else if (arg == "--roll-deg") {
      ok = parse_double(v, 0.0, 45.0, false, &m.roll_deg);
    } else if (arg == "--max-step-deg") {
      ok = parse_double(v, 0.0, 45.0, true, &m.max_step_deg);
    } else if (arg == "--drop-every") {
      ok = parse_int(v, 0, 100000, &o->drop_every) && o->drop_every != 1;
    } else if (arg == "--noise") {
      ok = parse_double(v, 0.0, 50.0, false, &o->noise);
    } else if (arg == "--compression") {
      o->compression = v;
      ok = v == "none" || v == "lz4" || v == "bz2";
    }
    if (!ok) return "bad value '" + v + "' for " + arg;
  }
  o->imaging = resolve_imaging(imaging, noise_given, &o->noise);
  if (o->photo.empty()) return "--photo PHOTO is required";
  if (o->out_bag.empty() && o->kitti_dir.empty())
    return "--out OUT.bag or --kitti-dir DIR is required";
  if (o->has_photo_K && !o->camera_file.empty())
    return "--camera and --K exclude each other (both give the photograph's intrinsics)";
  if (o->motion.yaw_deg == 0.0 && o->motion.pitch_deg == 0.0 && o->motion.roll_deg == 0.0)
    return "--yaw-deg, --pitch-deg and --roll-deg are all 0: no pan";
  return imaging_rate_problem(o->imaging, o->motion.rate);
}

PinholeCamera pan_camera(const PanOptions& o) {
  return PinholeCamera(o.focal, o.focal, 0.5 * (o.width - 1), 0.5 * (o.height - 1), o.width,
                       o.height);
}

}  // namespace render
}  // namespace hybrid_vo
