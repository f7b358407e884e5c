// hybrid_vo_render_pan: a virtual camera panning about its own centre inside a real photograph
// (render/photo_pan.h, render/pan_motion.h): real texture, a pure rotation as the exact ground
// truth, frames that a busy machine drops if asked. Writes the KITTI odometry layout and/or a
// bag in the renderer's layout.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <ros/time.h>
#include <rosbag/exceptions.h>

#include "hybrid_vo/conversion/bag_writing.h"
#include "hybrid_vo/datasets/kitti_writer.h"
#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/render/camera_path.h"
#include "hybrid_vo/render/pan_options.h"
#include "hybrid_vo/render/photo_pan.h"
#include "hybrid_vo/render/sequence.h"

namespace {

using namespace hybrid_vo::render;
namespace conversion = hybrid_vo::conversion;
namespace datasets = hybrid_vo::datasets;
using hybrid_vo::PinholeCamera;

// The photograph's intrinsics from --K (its size from the photograph) or its .camera file; false
// with the reason.
bool photo_intrinsics(const PanOptions& options, const cv::Mat& photo, PinholeCamera* camera,
                      std::string* error) {
  if (options.has_photo_K) {
    *camera = options.photo_K;
    camera->width = photo.cols;
    camera->height = photo.rows;
    return true;
  }
  const std::string file = options.camera_file.empty()
                               ? datasets::strecha_camera_of_image(options.photo)
                               : options.camera_file;
  if (file.empty()) {
    *error = "no intrinsics for " + options.photo +
             ": no .camera file in ../gt_dense_cameras/ or beside it; give --camera FILE or "
             "--K fx,fy,cx,cy";
    return false;
  }
  datasets::Frame frame;
  if (!datasets::read_strecha_camera(file, &frame, error)) return false;
  *camera = frame.camera.pinhole;
  if (camera->width != photo.cols || camera->height != photo.rows) {
    *error = file + " is for a " + std::to_string(camera->width) + "x" +
             std::to_string(camera->height) + " image, " + options.photo + " is " +
             std::to_string(photo.cols) + "x" + std::to_string(photo.rows);
    return false;
  }
  return true;
}

ros::Time stamp_of(int frame, double rate) {
  ros::Time t;
  t.fromNSec(frame_stamp_ns(frame, rate));
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string program = argc > 0 ? argv[0] : "hybrid_vo_render_pan";
  PanOptions options;
  const std::string error =
      parse_pan_args(std::vector<std::string>(argv + 1, argv + argc), &options);
  if (options.help) {
    std::cout << pan_usage(program);
    return 0;
  }
  if (!error.empty()) {
    std::cerr << "error: " << error << "\n" << pan_usage(program);
    return 2;
  }
  const bool to_bag = !options.out_bag.empty(), to_kitti = !options.kitti_dir.empty();
  if (const std::string why = to_bag ? check_writable_file(options.out_bag) : ""; !why.empty()) {
    std::cerr << "error: cannot write the bag: " << why << "\n";
    return 1;
  }

  try {
    const auto t_start = std::chrono::steady_clock::now();
    cv::Mat photo;
    int channels = 0;
    std::string read_error;
    if (!conversion::read_mono8(options.photo, &photo, &channels, &read_error)) {
      std::cerr << "error: " << read_error << "\n";
      return 1;
    }
    PinholeCamera photo_camera;
    if (!photo_intrinsics(options, photo, &photo_camera, &read_error)) {
      std::cerr << "error: " << read_error << "\n";
      return 1;
    }
    const PinholeCamera camera = pan_camera(options);
    const PanMotion motion = make_pan_motion(options.motion);
    const PhotoPan pan(photo, photo_camera, camera, options.noise, options.motion.seed,
                       options.imaging);
    // Every frame's views (over its exposure) must lie inside the photograph before anything is
    // written.
    for (int i = 0; i < options.motion.frames; ++i) {
      Eigen::Vector2d corner;
      bool inside = true;
      for (const Eigen::Matrix3d& R : pan.exposure_rotations(motion, i))
        inside = inside && view_inside_photo(pan_homography(photo_camera, camera, R), camera,
                                             photo_camera, 1.0, &corner);
      if (!inside) {
        std::fprintf(stderr,
                     "error: frame %d's view leaves the %dx%d photograph (a corner lands at "
                     "%.0f, %.0f): smaller --yaw-deg, --pitch-deg, --roll-deg or a longer "
                     "--focal\n",
                     i, photo_camera.width, photo_camera.height, corner.x(), corner.y());
        return 1;
      }
    }

    conversion::BagOutput out;
    std::string write_error;
    const rosbag::compression::CompressionType compression =
        options.compression == "lz4"   ? rosbag::compression::LZ4
        : options.compression == "bz2" ? rosbag::compression::BZ2
                                       : rosbag::compression::Uncompressed;
    if (to_bag && !out.open(options.out_bag, compression, &write_error)) {
      std::cerr << "error: cannot write the bag: " << write_error << "\n";
      return 1;
    }
    datasets::KittiWriter kitti;
    if (to_kitti && !kitti.open(options.kitti_dir, options.kitti_name, camera, 0.0, &write_error)) {
      std::cerr << "error: " << write_error << "\n";
      return 1;
    }
    const std::string frame_id = conversion::optical_frame("left");
    const std::string topic = conversion::camera_topic("left");
    const double rate = options.motion.rate;
    if (to_bag)
      out.write_tf_static(stamp_of(0, rate),
                          {conversion::stamped(conversion::kBaseFrame, frame_id, stamp_of(0, rate),
                                               conversion::to_transform(base_from_optical(),
                                                                        Eigen::Vector3d::Zero()))},
                          "/hybrid_vo_render_pan");

    int written = 0;
    double render_seconds = 0.0;
    for (int i = 0; i < options.motion.frames; ++i) {
      if (is_dropped(i, options.drop_every)) continue;
      const auto r0 = std::chrono::steady_clock::now();
      const cv::Mat image = pan.render_frame(motion, i);
      render_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
      const Eigen::Matrix3d R_world_from_camera = motion.R_first_from_camera(i);
      const ros::Time t = stamp_of(i, rate);
      if (to_bag) {
        out.write_image(topic + "/image_raw", frame_id, t, image);
        out.bag().write(topic + "/camera_info", t,
                        conversion::make_camera_info(camera, frame_id, t));
        out.write_ground_truth(conversion::ground_truth_frame(frame_id), t, R_world_from_camera,
                               Eigen::Vector3d::Zero());
      }
      const double time =
          1e-9 * static_cast<double>(frame_stamp_ns(i, rate) - frame_stamp_ns(0, rate));
      if (to_kitti && !kitti.add_frame(time, image, cv::Mat(), R_world_from_camera,
                                       Eigen::Vector3d::Zero(), &write_error)) {
        std::cerr << "error: " << write_error << "\n";
        return 1;
      }
      ++written;
    }
    if (to_bag && !out.commit(&write_error)) {
      std::cerr << "error: " << write_error << "\n";
      return 1;
    }
    if (to_kitti && !kitti.close(&write_error)) {
      std::cerr << "error: " << write_error << "\n";
      return 1;
    }
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    std::string outputs = options.out_bag;
    if (to_kitti)
      outputs +=
          (to_bag ? " and " : "") + kitti.sequence_dir() + " (poses " + kitti.poses_path() + ")";
    const PanMotionOptions& m = options.motion;
    const std::string imaging = describe(options.imaging) == "clean"
                                    ? ""
                                    : "imaging: " + describe(options.imaging) + "; ";
    std::printf(
        "rendered %d of %d frames (%d dropped) from %s: %dx%d, f %.0f px, %.0f Hz; yaw +-%g, "
        "pitch +-%g, roll +-%g deg, %.2f to %.2f deg per frame; prefilter sigma %.2f px; "
        "%s%.3f s per frame, %.1f s total -> %s\n",
        written, m.frames, m.frames - written, options.photo.c_str(), camera.width, camera.height,
        camera.fx, m.rate, m.yaw_deg, m.pitch_deg, m.roll_deg, motion.min_step_deg,
        motion.max_step_deg, pan.prefilter_sigma(), imaging.c_str(), render_seconds / written,
        total,
        outputs.c_str());
  } catch (const rosbag::BagException& e) {
    std::cerr << "error: cannot write the bag '" << options.out_bag << "': " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
