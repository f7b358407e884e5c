#include "hybrid_vo/conversion/kitti_to_bag.h"

#include <cmath>
#include <exception>
#include <filesystem>
#include <sstream>

#include <Eigen/Core>

#include "hybrid_vo/conversion/bag_writing.h"
#include "hybrid_vo/datasets/kitti.h"
#include "hybrid_vo/datasets/text_file.h"
#include "hybrid_vo/render/camera_path.h"

namespace hybrid_vo {
namespace conversion {
namespace {

namespace fs = std::filesystem;
using datasets::fail;
using datasets::located;

// The poses file to use: the given one, else <root>/poses/<name>.txt if present, else none.
std::string poses_path_of(const KittiBagOptions& options, const fs::path& sequence_dir) {
  if (!options.poses.empty()) return options.poses;
  const fs::path guess = (sequence_dir / ".." / ".." / "poses").lexically_normal() /
                         (sequence_dir.filename().string() + ".txt");
  std::error_code ec;
  return fs::exists(guess, ec) ? guess.string() : "";
}

bool check_images(const std::string& sequence_dir, int camera, size_t frames,
                  const std::string& times_path, std::string* error) {
  const std::string dir = (fs::path(sequence_dir) / ("image_" + std::to_string(camera))).string();
  const int count = datasets::count_kitti_images(sequence_dir, camera);
  if (count < 0) return fail(error, located(dir, 0, "no such directory"));
  // Each frame's file first, so that a missing one is named; then the count, for extra files.
  for (size_t k = 0; k < frames; ++k) {
    const std::string path = datasets::kitti_image_path(sequence_dir, camera, k);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return fail(error, located(path, 0, "no such image"));
  }
  if (static_cast<size_t>(count) != frames)
    return fail(error, located(dir, 0,
                               std::to_string(count) + " images for " + std::to_string(frames) +
                                   " timestamps in " + times_path));
  return true;
}

}  // namespace

std::string kitti_usage(const std::string& program) {
  std::ostringstream s;
  s << "Usage: " << program << " --sequence DIR --out OUT.bag [options]\n"
    << "Converts a KITTI odometry sequence (DIR = <root>/sequences/<name> with calib.txt,\n"
    << "times.txt, image_0/ and with --stereo image_1/) into a bag: /camera/left/{image_raw,\n"
    << "camera_info} (and /camera/right/...), /tf_static, and with poses /ground_truth/pose and\n"
    << "/tf world -> gt_camera_left_optical.\n"
    << "  --poses FILE      camera-to-world poses (default <root>/poses/<name>.txt if present)\n"
    << "  --stereo          also the right camera (image_1, P1)\n"
    << "  --start-time T    seconds added to times.txt (default 1)\n"
    << "  --compressed png|jpeg  images as sensor_msgs/CompressedImage on .../image_raw/compressed\n"
    << "                    (as robots record them) instead of raw on .../image_raw\n"
    << "  --jpeg-quality Q  with --compressed jpeg: quality 1..100 (default 95)\n";
  return s.str();
}

std::string parse_kitti_args(const std::vector<std::string>& args, KittiBagOptions* o) {
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
    if (arg != "--sequence" && arg != "--poses" && arg != "--out" && arg != "--start-time" &&
        arg != "--compressed" && arg != "--jpeg-quality")
      return "unknown argument '" + arg + "'";
    if (i + 1 >= args.size() || args[i + 1].empty()) return arg + " needs a value";
    const std::string& v = args[++i];
    if (arg == "--sequence") o->sequence_dir = v;
    if (arg == "--poses") o->poses = v;
    if (arg == "--out") o->out_bag = v;
    if (arg == "--start-time" && (!datasets::parse_double(v, &o->start_time) || o->start_time < 0))
      return "bad value '" + v + "' for --start-time (seconds, >= 0)";
    if (arg == "--compressed" && !parse_compressed_images(v, &o->images))
      return "bad value '" + v + "' for --compressed (png or jpeg)";
    if (arg == "--jpeg-quality" && !parse_jpeg_quality(v, &o->images))
      return "bad value '" + v + "' for --jpeg-quality (1..100)";
  }
  if (o->sequence_dir.empty()) return "--sequence DIR is required";
  if (o->out_bag.empty()) return "--out OUT.bag is required";
  return "";
}

bool convert_kitti(const KittiBagOptions& options, std::string* error, KittiBagSummary* summary) {
  fs::path sequence_dir = fs::path(options.sequence_dir).lexically_normal();
  if (sequence_dir.filename().empty()) sequence_dir = sequence_dir.parent_path();  // trailing '/'
  std::error_code ec;
  if (!fs::is_directory(sequence_dir, ec))
    return fail(error, located(options.sequence_dir, 0, "no such directory"));
  const std::string dir = sequence_dir.string();
  const std::string calib_path = (sequence_dir / "calib.txt").string();
  const std::string times_path = (sequence_dir / "times.txt").string();

  datasets::KittiCalibration calibration;
  std::vector<double> times;
  if (!datasets::read_kitti_calibration(calib_path, &calibration, error) ||
      !datasets::read_kitti_times(times_path, &times, error))
    return false;
  if (options.stereo && !calibration.P1.present())
    return fail(error, located(calib_path, 0, "no 'P1:' line, which --stereo needs"));
  const std::string poses_path = poses_path_of(options, sequence_dir);
  std::vector<datasets::KittiPose> poses;
  if (!poses_path.empty()) {
    if (!datasets::read_kitti_poses(poses_path, &poses, error)) return false;
    if (poses.size() != times.size())
      return fail(error, located(poses_path, 0,
                                 std::to_string(poses.size()) + " poses for " +
                                     std::to_string(times.size()) + " frames in " + times_path));
  }
  for (int camera = 0; camera < (options.stereo ? 2 : 1); ++camera)
    if (!check_images(dir, camera, times.size(), times_path, error)) return false;
  if (!(options.start_time + times.front() > 0.0))
    return fail(error, located(times_path, 1,
                               "the first stamp is 0, which a bag cannot hold: pass "
                               "--start-time > 0"));

  BagOutput out;
  if (!out.open(options.out_bag, rosbag::compression::LZ4, error)) return false;
  out.set_image_format(options.images);
  const std::string left = optical_frame("left"), right = optical_frame("right");
  const ros::Time t0(options.start_time + times.front());
  const Eigen::Matrix3d R_base_optical = render::base_from_optical();
  std::vector<geometry_msgs::TransformStamped> statics = {
      stamped(kBaseFrame, left, t0, to_transform(R_base_optical, Eigen::Vector3d::Zero()))};
  if (options.stereo) {
    const Eigen::Vector3d right_in_base =
        R_base_optical * Eigen::Vector3d(calibration.baseline(), 0.0, 0.0);
    statics.push_back(
        stamped(kBaseFrame, right, t0, to_transform(R_base_optical, right_in_base)));
  }
  try {
    out.write_tf_static(t0, statics, "/hybrid_vo_kitti_to_bag");
    cv::Mat first;
    int first_channels = 0;
    for (size_t k = 0; k < times.size(); ++k) {
      const ros::Time stamp(options.start_time + times[k]);
      for (int camera = 0; camera < (options.stereo ? 2 : 1); ++camera) {
        const std::string path = datasets::kitti_image_path(dir, camera, k);
        cv::Mat image;
        int channels = 0;
        if (!read_mono8(path, &image, &channels, error)) return false;
        if (first.empty()) {
          first = image;
          first_channels = channels;
        }
        if (image.size() != first.size())
          return fail(error, located(path, 0,
                                     "image is " + std::to_string(image.cols) + "x" +
                                         std::to_string(image.rows) + ", the first was " +
                                         std::to_string(first.cols) + "x" +
                                         std::to_string(first.rows)));
        // A colour frame among grey ones is another camera's (KITTI's image_2/3), not this one.
        if (channels != first_channels)
          return fail(error, located(path, 0,
                                     std::to_string(channels) + "-channel image, the first was " +
                                         std::to_string(first_channels) + "-channel"));
        const datasets::KittiProjection& P = camera == 0 ? calibration.P0 : calibration.P1;
        PinholeCamera K = P.camera;
        K.width = image.cols;
        K.height = image.rows;
        const std::string& frame = camera == 0 ? left : right;
        const std::string topic = camera_topic(camera == 0 ? "left" : "right");
        out.write_image(topic + "/image_raw", frame, stamp, image);
        out.bag().write(topic + "/camera_info", stamp,
                        make_camera_info(K, frame, stamp, P.P(0, 3)));
      }
      if (!poses.empty())
        out.write_ground_truth(ground_truth_frame(left), stamp, poses[k].R_wc, poses[k].c_w);
    }
    if (!out.commit(error)) return false;
    if (summary) {
      summary->frames = static_cast<int>(times.size());
      summary->width = first.cols;
      summary->height = first.rows;
      summary->poses_path = poses_path;
    }
  } catch (const std::exception& e) {
    // rosbag's, and any other (cv_bridge, allocation): the BagOutput still removes its file.
    return fail(error, located(options.out_bag, 0, e.what()));
  }
  return true;
}

}  // namespace conversion
}  // namespace hybrid_vo
