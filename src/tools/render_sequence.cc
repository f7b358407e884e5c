// hybrid_vo_render_sequence: renders the synthetic Manhattan sequence (render/sequence.h) into a
// bag with images, camera_info, ground-truth poses and tf (the demo's default data and the
// rostest fixture), and/or into the KITTI odometry layout (the ROS-free tools' input).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <ros/time.h>
#include <rosbag/exceptions.h>
#include <opencv2/imgcodecs.hpp>

#include "hybrid_vo/conversion/bag_writing.h"
#include "hybrid_vo/datasets/kitti_writer.h"
#include "hybrid_vo/render/sequence.h"

namespace {

using hybrid_vo::conversion::BagOutput;
using namespace hybrid_vo::render;

ros::Time stamp_of(int frame, double rate) {
  ros::Time t;
  t.fromNSec(frame_stamp_ns(frame, rate));
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string program = argc > 0 ? argv[0] : "hybrid_vo_render_sequence";
  SequenceOptions options;
  const std::string error =
      parse_sequence_args(std::vector<std::string>(argv + 1, argv + argc), &options);
  if (options.help) {
    std::cout << sequence_usage(program);
    return 0;
  }
  if (!error.empty()) {
    std::cerr << "error: " << error << "\n" << sequence_usage(program);
    return 2;
  }
  const bool to_bag = !options.out_bag.empty(), to_kitti = !options.kitti_dir.empty();
  if (const std::string why = to_bag ? check_writable_file(options.out_bag) : ""; !why.empty()) {
    std::cerr << "error: cannot write the bag: " << why << "\n";
    return 1;
  }
  if (!options.png_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.png_dir, ec);
    if (ec || !std::filesystem::is_directory(options.png_dir)) {
      std::cerr << "error: cannot create --png-dir '" << options.png_dir
                << "': " << (ec ? ec.message() : "not a directory") << "\n";
      return 1;
    }
  }

  try {
    const auto t_start = std::chrono::steady_clock::now();
    const Sequence seq = make_sequence(options);
    namespace conversion = hybrid_vo::conversion;
    const rosbag::compression::CompressionType compression =
        options.compression == "lz4"   ? rosbag::compression::LZ4
        : options.compression == "bz2" ? rosbag::compression::BZ2
                                       : rosbag::compression::Uncompressed;
    BagOutput out;
    std::string bag_error;
    if (to_bag && !out.open(options.out_bag, compression, &bag_error)) {
      std::cerr << "error: cannot write the bag: " << bag_error << "\n";
      return 1;
    }
    hybrid_vo::datasets::KittiWriter kitti;
    std::string kitti_error;
    if (to_kitti && !kitti.open(options.kitti_dir, options.kitti_name, seq.camera,
                                options.stereo ? options.baseline : 0.0, &kitti_error)) {
      std::cerr << "error: " << kitti_error << "\n";
      return 1;
    }
    conversion::BagImageFormat image_format;
    if (!options.compressed_images.empty())
      conversion::parse_compressed_images(options.compressed_images, &image_format);  // checked
    image_format.jpeg_quality = options.jpeg_quality;
    out.set_image_format(image_format);
    const std::string left = conversion::optical_frame("left");
    const std::string right = conversion::optical_frame("right");

    const ros::Time t0 = stamp_of(0, options.rate);
    std::vector<geometry_msgs::TransformStamped> statics = {conversion::stamped(
        conversion::kBaseFrame, left, t0,
        conversion::to_transform(base_from_optical(), Eigen::Vector3d::Zero()))};
    if (options.stereo) {
      const Eigen::Vector3d right_in_base =
          base_from_optical() * Eigen::Vector3d(options.baseline, 0.0, 0.0);
      statics.push_back(
          conversion::stamped(conversion::kBaseFrame, right, t0,
                              conversion::to_transform(base_from_optical(), right_in_base)));
    }
    if (to_bag) out.write_tf_static(t0, statics, "/hybrid_vo_render_sequence");

    const double tx_right = -seq.camera.fx * options.baseline;
    double render_seconds = 0.0;
    size_t exposure_views = 0;
    for (int i = 0; i < seq.options.frames; ++i) {
      const ros::Time t = stamp_of(i, options.rate);
      cv::Mat images[2];
      for (int side = 0; side < (options.stereo ? 2 : 1); ++side) {
        const bool is_right = side == 1;
        const auto r0 = std::chrono::steady_clock::now();
        const RenderedView view = render_frame(seq, i, is_right);
        render_seconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
        exposure_views += exposure_poses(seq, i, is_right).size();
        images[side] = view.image;
        const std::string prefix = conversion::camera_topic(is_right ? "right" : "left");
        const std::string& frame = is_right ? right : left;
        if (to_bag) {
          out.write_image(prefix + "/image_raw", frame, t, view.image);
          out.bag().write(prefix + "/camera_info", t,
                          seq.lens.model == hybrid_vo::LensModel::kEquidistant
                              ? conversion::make_camera_info(
                                    seq.camera, frame, t, is_right ? tx_right : 0.0,
                                    "equidistant",
                                    {seq.lens.distortion.begin(), seq.lens.distortion.begin() + 4})
                              : conversion::make_camera_info(seq.camera, frame, t,
                                                             is_right ? tx_right : 0.0));
        }
        if (!options.png_dir.empty()) {
          char name[64];
          std::snprintf(name, sizeof(name), "%s_%06d.png", is_right ? "right" : "left", i);
          const std::string file = (std::filesystem::path(options.png_dir) / name).string();
          if (!cv::imwrite(file, view.image)) {
            std::cerr << "error: cannot write " << file << "\n";
            return 1;
          }
        }
      }
      const CameraPose& pose = seq.trajectory.poses[i];
      if (to_bag)
        out.write_ground_truth(conversion::ground_truth_frame(left), t, pose.R_world_from_camera,
                               pose.centre);
      // KITTI's times start at 0; hybrid_vo_kitti_to_bag adds the 1 s the bag starts at.
      const double time = 1e-9 * static_cast<double>(frame_stamp_ns(i, options.rate) -
                                                     frame_stamp_ns(0, options.rate));
      if (to_kitti && !kitti.add_frame(time, images[0], images[1], pose.R_world_from_camera,
                                       pose.centre, &kitti_error)) {
        std::cerr << "error: " << kitti_error << "\n";
        return 1;
      }
    }
    if (to_bag && !out.commit(&bag_error)) {
      std::cerr << "error: " << bag_error << "\n";
      return 1;
    }
    if (to_kitti && !kitti.close(&kitti_error)) {
      std::cerr << "error: " << kitti_error << "\n";
      return 1;
    }
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    const int views = seq.options.frames * (options.stereo ? 2 : 1);
    const std::string motion =
        options.motion == Motion::kWalk ? "" : std::string(", ") + to_string(options.motion);
    std::string outputs = options.out_bag;
    if (to_kitti)
      outputs += (to_bag ? " and " : "") + kitti.sequence_dir() + " (poses " + kitti.poses_path() +
                 ")";
    std::string imaging;
    if (describe(options.imaging) != "clean") {
      char instants[64];
      std::snprintf(instants, sizeof(instants), " (%.1f instants per view)",
                    static_cast<double>(exposure_views) / views);
      imaging = ", imaging: " + describe(options.imaging) +
                (options.imaging.exposure_ms > 0.0 ? instants : "");
    }
    std::printf(
        "rendered %d frames (%s, %dx%d, %s%s, %s%s, %.0f Hz%s), path %.1f m, turned %.0f deg, "
        "%.3f s per view, %.1f s total -> %s\n",
        seq.options.frames, options.stereo ? "stereo" : "mono", options.width, options.height,
        options.fisheye_fov > 0.0
            ? (std::to_string(static_cast<int>(std::lround(options.fisheye_fov))) +
               " deg equidistant, ").c_str()
            : "",
        to_string(options.scene), to_string(options.texture),
        motion.c_str(), options.rate, imaging.c_str(),
        seq.trajectory.length, seq.trajectory.total_turn_deg, render_seconds / views, total,
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
