#pragma once

// What every bag writer of ours shares (the renderer and the KITTI and LaMAR converters): topic
// and frame names, camera_info, images, ground truth and latched static transforms, an output
// file that only appears under its name once it is complete, and input images read so that a
// damaged one stops the conversion instead of going into the bag.
//
// Layout of a bag (the launch files rely on it):
//   /camera/<name>/image_raw     sensor_msgs/Image mono8, frame camera_<name>_optical; or, with
//                                compressed images (BagImageFormat), /camera/<name>/image_raw/
//                                compressed, sensor_msgs/CompressedImage PNG or JPEG
//   /camera/<name>/camera_info   sensor_msgs/CameraInfo of the same stamp and frame
//   /tf_static                   base_link -> camera_<name>_optical (REP 103 body, z-forward
//                                optical frame), latched
//   /ground_truth/pose           geometry_msgs/PoseStamped in world: the camera-to-world pose of
//                                the first camera (hybrid_vo_eval_trajectory --gt reads it)
//   /tf                          world -> gt_camera_<name>_optical, the same pose

#include <string>
#include <vector>

#include <Eigen/Core>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/TransformStamped.h>
#include <opencv2/core.hpp>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>

#include "hybrid_vo/geometry/camera.h"

namespace hybrid_vo {
namespace conversion {

extern const char kWorldFrame[];        // "world"
extern const char kBaseFrame[];         // "base_link"
extern const char kGroundTruthTopic[];  // "/ground_truth/pose"

std::string camera_topic(const std::string& name);   // "/camera/<name>"
std::string optical_frame(const std::string& name);  // "camera_<name>_optical"
std::string ground_truth_frame(const std::string& camera_frame);  // "gt_<camera_frame>"

// A ROS graph name from an arbitrary id: characters other than letters, digits and '_' become
// '_', and a name that does not start with a letter gets the prefix "cam_".
std::string sanitize_name(const std::string& id);

geometry_msgs::Transform to_transform(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
geometry_msgs::TransformStamped stamped(const std::string& parent, const std::string& child,
                                        const ros::Time& stamp,
                                        const geometry_msgs::Transform& transform);

// camera_info with K from `camera` (its width and height too), R = I, P = [K | (tx, 0, 0)]
// (tx = -fx * baseline for the right camera of a rectified pair) and the given distortion.
sensor_msgs::CameraInfo make_camera_info(const PinholeCamera& camera, const std::string& frame,
                                         const ros::Time& stamp, double tx = 0.0,
                                         const std::string& distortion_model = "plumb_bob",
                                         const std::vector<double>& D = {0, 0, 0, 0, 0});

// How a bag holds its images: raw, or compressed as compressed_image_transport publishes them
// and robots record them: sensor_msgs/CompressedImage on <image topic>/compressed with the
// format "mono8; png compressed " or "mono8; jpeg compressed mono8".
struct BagImageFormat {
  enum Kind { kRaw, kPng, kJpeg } kind = kRaw;
  int jpeg_quality = 95;  // 1..100
};
// The value of a converter's --compressed: "png" or "jpeg". False for anything else.
bool parse_compressed_images(const std::string& value, BagImageFormat* format);
// The value of --jpeg-quality: an integer in 1..100.
bool parse_jpeg_quality(const std::string& value, BagImageFormat* format);
const char* to_string(BagImageFormat::Kind kind);

// A bag written to OUT.tmp and renamed to OUT by commit(), so that a failed conversion never
// leaves a bag that looks complete; an uncommitted file is deleted by the destructor.
class BagOutput {
 public:
  BagOutput() = default;
  BagOutput(const BagOutput&) = delete;
  BagOutput& operator=(const BagOutput&) = delete;
  ~BagOutput();

  // Fails (with the reason) when the folder of `path` is missing or not writable.
  bool open(const std::string& path, rosbag::compression::CompressionType compression,
            std::string* error);
  bool commit(std::string* error);
  rosbag::Bag& bag() { return bag_; }

  // Raw by default.
  void set_image_format(const BagImageFormat& format) { image_format_ = format; }
  // An image on `topic` (raw), or compressed on `topic`/compressed; throws std::runtime_error
  // when the encoder fails.
  void write_image(const std::string& topic, const std::string& frame, const ros::Time& stamp,
                   const cv::Mat& mono8);
  // The camera-to-world pose (R, centre) on /ground_truth/pose and as world -> child on /tf.
  void write_ground_truth(const std::string& child, const ros::Time& stamp,
                          const Eigen::Matrix3d& R_world_camera, const Eigen::Vector3d& centre);
  // /tf_static with a latching connection header, as a tf2 static broadcaster publishes it, so
  // that rosbag play latches it and a recorder gets it too.
  void write_tf_static(const ros::Time& stamp,
                       const std::vector<geometry_msgs::TransformStamped>& transforms,
                       const std::string& callerid);

 private:
  rosbag::Bag bag_;
  BagImageFormat image_format_;
  std::string path_, tmp_path_;
  bool committed_ = false;
};

// An image file on its way into a bag: false with "path: reason" for a missing or empty file,
// one OpenCV cannot decode (or whose header claims a size OpenCV refuses), a JPEG cut short
// (libjpeg only warns "Premature end of JPEG file" and fills the missing rows with grey), and
// one of more than 8 bits per channel (IMREAD_GRAYSCALE would scale it down without a word).
// *mono8 is what cv::imread(path, IMREAD_GRAYSCALE) gives (EXIF orientation applied, colour
// turned grey by the decoder); *channels is 1 for a grey file and 3 for a colour one, so that a
// converter can refuse a frame unlike the rest of its stream.
bool read_mono8(const std::string& path, cv::Mat* mono8, int* channels, std::string* error);

}  // namespace conversion
}  // namespace hybrid_vo
