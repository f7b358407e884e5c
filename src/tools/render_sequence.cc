// hybrid_vo_render_sequence: renders the synthetic Manhattan sequence (render/sequence.h) into a
// bag with images, camera_info, ground-truth poses and tf; the demo's default data and the
// rostest fixture.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>
#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "render/sequence.h"

namespace {

using hybrid_vo::PinholeCamera;
using namespace hybrid_vo::render;

const char kWorld[] = "world";
const char kGroundTruth[] = "gt_camera_left_optical";
const char kBase[] = "base_link";
const char kLeft[] = "camera_left_optical";
const char kRight[] = "camera_right_optical";

ros::Time stamp_of(int frame, double rate) {
  ros::Time t;
  t.fromNSec(frame_stamp_ns(frame, rate));
  return t;
}

// ROS camera_info of a rectified camera; tx = -fx * baseline for the right camera of a pair.
sensor_msgs::CameraInfo camera_info(const PinholeCamera& cam, const std::string& frame,
                                    const ros::Time& stamp, double tx) {
  sensor_msgs::CameraInfo info;
  info.header.stamp = stamp;
  info.header.frame_id = frame;
  info.width = cam.width;
  info.height = cam.height;
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  info.K = {cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {cam.fx, 0.0, cam.cx, tx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

geometry_msgs::Transform to_transform(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Quaterniond q(R);
  if (q.w() < 0.0) q.coeffs() *= -1.0;  // the same rotation; w >= 0 reads better
  geometry_msgs::Transform tf;
  tf.translation.x = t.x();
  tf.translation.y = t.y();
  tf.translation.z = t.z();
  tf.rotation.x = q.x();
  tf.rotation.y = q.y();
  tf.rotation.z = q.z();
  tf.rotation.w = q.w();
  return tf;
}

geometry_msgs::TransformStamped stamped(const std::string& parent, const std::string& child,
                                        const ros::Time& stamp,
                                        const geometry_msgs::Transform& tf) {
  geometry_msgs::TransformStamped s;
  s.header.stamp = stamp;
  s.header.frame_id = parent;
  s.child_frame_id = child;
  s.transform = tf;
  return s;
}

void write_image(rosbag::Bag* bag, const std::string& topic, const std::string& frame,
                 const ros::Time& stamp, const cv::Mat& image) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frame;
  bag->write(topic, stamp,
             *cv_bridge::CvImage(header, sensor_msgs::image_encodings::MONO8, image).toImageMsg());
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
  if (const std::string why = check_writable_file(options.out_bag); !why.empty()) {
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
    rosbag::Bag bag;
    bag.open(options.out_bag, rosbag::bagmode::Write);
    if (options.compression == "lz4") bag.setCompression(rosbag::compression::LZ4);
    if (options.compression == "bz2") bag.setCompression(rosbag::compression::BZ2);

    // Static transforms, latched as a tf2 static broadcaster would publish them.
    const ros::Time t0 = stamp_of(0, options.rate);
    tf2_msgs::TFMessage statics;
    statics.transforms.push_back(
        stamped(kBase, kLeft, t0, to_transform(base_from_optical(), Eigen::Vector3d::Zero())));
    if (options.stereo) {
      const Eigen::Vector3d right_in_base =
          base_from_optical() * Eigen::Vector3d(options.baseline, 0.0, 0.0);
      statics.transforms.push_back(
          stamped(kBase, kRight, t0, to_transform(base_from_optical(), right_in_base)));
    }
    // A given connection header replaces rosbag's own, so it carries the type fields too.
    auto latched = boost::make_shared<ros::M_string>();
    (*latched)["topic"] = "/tf_static";
    (*latched)["type"] = ros::message_traits::datatype<tf2_msgs::TFMessage>();
    (*latched)["md5sum"] = ros::message_traits::md5sum<tf2_msgs::TFMessage>();
    (*latched)["message_definition"] = ros::message_traits::definition<tf2_msgs::TFMessage>();
    (*latched)["callerid"] = "/hybrid_vo_render_sequence";
    (*latched)["latching"] = "1";
    bag.write("/tf_static", t0, statics, latched);

    const double tx_right = -seq.camera.fx * options.baseline;
    double render_seconds = 0.0;
    for (int i = 0; i < options.frames; ++i) {
      const ros::Time t = stamp_of(i, options.rate);
      for (int side = 0; side < (options.stereo ? 2 : 1); ++side) {
        const bool right = side == 1;
        const auto r0 = std::chrono::steady_clock::now();
        const RenderedView view = render_frame(seq, i, right);
        render_seconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
        const std::string prefix = right ? "/camera/right" : "/camera/left";
        const std::string frame = right ? kRight : kLeft;
        write_image(&bag, prefix + "/image_raw", frame, t, view.image);
        bag.write(prefix + "/camera_info", t,
                  camera_info(seq.camera, frame, t, right ? tx_right : 0.0));
        if (!options.png_dir.empty()) {
          char name[64];
          std::snprintf(name, sizeof(name), "%s_%06d.png", right ? "right" : "left", i);
          const std::string file = (std::filesystem::path(options.png_dir) / name).string();
          if (!cv::imwrite(file, view.image)) {
            std::cerr << "error: cannot write " << file << "\n";
            return 1;
          }
        }
      }
      const CameraPose& pose = seq.trajectory.poses[i];
      const geometry_msgs::Transform tf = to_transform(pose.R_world_from_camera, pose.centre);
      geometry_msgs::PoseStamped gt;
      gt.header.stamp = t;
      gt.header.frame_id = kWorld;
      gt.pose.position.x = tf.translation.x;
      gt.pose.position.y = tf.translation.y;
      gt.pose.position.z = tf.translation.z;
      gt.pose.orientation = tf.rotation;
      bag.write("/ground_truth/pose", t, gt);
      tf2_msgs::TFMessage tf_msg;
      tf_msg.transforms.push_back(stamped(kWorld, kGroundTruth, t, tf));
      bag.write("/tf", t, tf_msg);
    }
    bag.close();
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    const int views = options.frames * (options.stereo ? 2 : 1);
    std::printf(
        "rendered %d frames (%s, %dx%d, %s, %.0f Hz), path %.1f m, turned %.0f deg, "
        "%.3f s per view, %.1f s total -> %s\n",
        options.frames, options.stereo ? "stereo" : "mono", options.width, options.height,
        to_string(options.scene), options.rate, seq.trajectory.length,
        seq.trajectory.total_turn_deg, render_seconds / views, total, options.out_bag.c_str());
  } catch (const rosbag::BagException& e) {
    std::cerr << "error: cannot write the bag '" << options.out_bag << "': " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
