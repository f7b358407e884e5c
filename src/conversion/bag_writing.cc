#include "hybrid_vo/conversion/bag_writing.h"

#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <cv_bridge/cv_bridge.h>
#include <Eigen/Geometry>
#include <geometry_msgs/PoseStamped.h>
#include <opencv2/imgcodecs.hpp>
#include <rosbag/exceptions.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>

#include "hybrid_vo/features/image_codec.h"

namespace hybrid_vo {
namespace conversion {

const char kWorldFrame[] = "world";
const char kBaseFrame[] = "base_link";
const char kGroundTruthTopic[] = "/ground_truth/pose";

std::string camera_topic(const std::string& name) { return "/camera/" + name; }
std::string optical_frame(const std::string& name) { return "camera_" + name + "_optical"; }
std::string ground_truth_frame(const std::string& camera_frame) { return "gt_" + camera_frame; }

std::string sanitize_name(const std::string& id) {
  std::string name = id;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
  if (name.empty() || !std::isalpha(static_cast<unsigned char>(name[0]))) name = "cam_" + name;
  return name;
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
                                        const geometry_msgs::Transform& transform) {
  geometry_msgs::TransformStamped s;
  s.header.stamp = stamp;
  s.header.frame_id = parent;
  s.child_frame_id = child;
  s.transform = transform;
  return s;
}

sensor_msgs::CameraInfo make_camera_info(const PinholeCamera& cam, const std::string& frame,
                                         const ros::Time& stamp, double tx,
                                         const std::string& distortion_model,
                                         const std::vector<double>& D) {
  sensor_msgs::CameraInfo info;
  info.header.stamp = stamp;
  info.header.frame_id = frame;
  info.width = cam.width;
  info.height = cam.height;
  info.distortion_model = distortion_model;
  info.D = D;
  info.K = {cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {cam.fx, 0.0, cam.cx, tx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

BagOutput::~BagOutput() {
  if (committed_ || tmp_path_.empty()) return;
  try {
    bag_.close();
  } catch (const rosbag::BagException&) {
  }
  std::error_code ec;
  std::filesystem::remove(tmp_path_, ec);
}

bool BagOutput::open(const std::string& path, rosbag::compression::CompressionType compression,
                     std::string* error) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : ".";
  if (path.empty() || fs::is_directory(path, ec)) {
    *error = "'" + path + "' is not a file name";
    return false;
  }
  if (!fs::is_directory(dir, ec) || ::access(dir.c_str(), W_OK) != 0) {
    *error = path + ": folder '" + dir.string() + "' is missing or not writable";
    return false;
  }
  path_ = path;
  tmp_path_ = path + ".tmp";
  try {
    bag_.open(tmp_path_, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    *error = tmp_path_ + ": " + e.what();
    tmp_path_.clear();
    return false;
  }
  bag_.setCompression(compression);
  return true;
}

bool BagOutput::commit(std::string* error) {
  try {
    bag_.close();
  } catch (const rosbag::BagException& e) {
    *error = tmp_path_ + ": " + e.what();
    return false;
  }
  std::error_code ec;
  std::filesystem::rename(tmp_path_, path_, ec);
  if (ec) {
    *error = "cannot rename " + tmp_path_ + " to " + path_ + ": " + ec.message();
    return false;
  }
  committed_ = true;
  return true;
}

bool parse_compressed_images(const std::string& value, BagImageFormat* format) {
  if (value == "png") format->kind = BagImageFormat::kPng;
  else if (value == "jpeg" || value == "jpg") format->kind = BagImageFormat::kJpeg;
  else return false;
  return true;
}

bool parse_jpeg_quality(const std::string& value, BagImageFormat* format) {
  char* end = nullptr;
  const long quality = std::strtol(value.c_str(), &end, 10);
  if (value.empty() || *end || quality < 1 || quality > 100) return false;
  format->jpeg_quality = static_cast<int>(quality);
  return true;
}

const char* to_string(BagImageFormat::Kind kind) {
  switch (kind) {
    case BagImageFormat::kPng: return "png";
    case BagImageFormat::kJpeg: return "jpeg";
    case BagImageFormat::kRaw: break;
  }
  return "raw";
}

void BagOutput::write_image(const std::string& topic, const std::string& frame,
                            const ros::Time& stamp, const cv::Mat& mono8) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = frame;
  if (image_format_.kind == BagImageFormat::kRaw) {
    bag_.write(topic, stamp,
               *cv_bridge::CvImage(header, sensor_msgs::image_encodings::MONO8, mono8).toImageMsg());
    return;
  }
  sensor_msgs::CompressedImage image;
  image.header = header;
  const bool png = image_format_.kind == BagImageFormat::kPng;
  // compressed_image_transport's format field: "<encoding>; <codec> compressed [<target>]".
  image.format = png ? "mono8; png compressed " : "mono8; jpeg compressed mono8";
  const std::vector<int> params =
      png ? std::vector<int>{} : std::vector<int>{cv::IMWRITE_JPEG_QUALITY, image_format_.jpeg_quality};
  if (!cv::imencode(png ? ".png" : ".jpg", mono8, image.data, params))
    throw std::runtime_error(std::string("cannot encode ") + to_string(image_format_.kind) +
                             " for " + topic);
  bag_.write(topic + "/compressed", stamp, image);
}

void BagOutput::write_ground_truth(const std::string& child, const ros::Time& stamp,
                                   const Eigen::Matrix3d& R_world_camera,
                                   const Eigen::Vector3d& centre) {
  const geometry_msgs::Transform tf = to_transform(R_world_camera, centre);
  geometry_msgs::PoseStamped gt;
  gt.header.stamp = stamp;
  gt.header.frame_id = kWorldFrame;
  gt.pose.position.x = tf.translation.x;
  gt.pose.position.y = tf.translation.y;
  gt.pose.position.z = tf.translation.z;
  gt.pose.orientation = tf.rotation;
  bag_.write(kGroundTruthTopic, stamp, gt);
  tf2_msgs::TFMessage message;
  message.transforms.push_back(stamped(kWorldFrame, child, stamp, tf));
  bag_.write("/tf", stamp, message);
}

void BagOutput::write_tf_static(const ros::Time& stamp,
                                const std::vector<geometry_msgs::TransformStamped>& transforms,
                                const std::string& callerid) {
  tf2_msgs::TFMessage statics;
  statics.transforms = transforms;
  // A given connection header replaces rosbag's own, so it carries the type fields too.
  auto latched = boost::make_shared<ros::M_string>();
  (*latched)["topic"] = "/tf_static";
  (*latched)["type"] = ros::message_traits::datatype<tf2_msgs::TFMessage>();
  (*latched)["md5sum"] = ros::message_traits::md5sum<tf2_msgs::TFMessage>();
  (*latched)["message_definition"] = ros::message_traits::definition<tf2_msgs::TFMessage>();
  (*latched)["callerid"] = callerid;
  (*latched)["latching"] = "1";
  bag_.write("/tf_static", stamp, statics, latched);
}

bool read_mono8(const std::string& path, cv::Mat* mono8, int* channels, std::string* error) {
  auto failed = [&](const std::string& reason) {
    *error = path + ": " + reason;
    return false;
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return failed("no such image");
  if (!std::filesystem::is_regular_file(path, ec)) return failed("not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return failed("cannot read");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  if (bytes.empty()) return failed("empty file, not an image");
  // OpenCV's own test for a JPEG, whatever the file's extension.
  const bool jpeg = bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
  if (jpeg && !jpeg_reaches_end(bytes))
    return failed("JPEG cut short (no end-of-image marker): cannot decode image");
  try {
    // Decoded in its own depth and colours first, so that depth and channels can be checked;
    // a colour file is decoded again in grey, so that its pixels are exactly what
    // IMREAD_GRAYSCALE gives (libjpeg's grey output, not cvtColor's).
    const cv::Mat stored = cv::imdecode(bytes, cv::IMREAD_ANYCOLOR | cv::IMREAD_ANYDEPTH);
    if (stored.empty()) return failed("cannot decode image");
    if (stored.depth() != CV_8U)
      return failed(std::to_string(8 * stored.elemSize1()) + "-bit " +
                    (stored.depth() >= CV_32F ? "floating-point " : "") +
                    "image, but a bag holds 8-bit mono8: convert it to 8 bits first");
    *channels = stored.channels();
    *mono8 = stored.channels() == 1 ? stored : cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
    if (mono8->empty()) return failed("cannot decode image");
  } catch (const cv::Exception& e) {
    // A header that claims a size beyond OpenCV's limits (CV_IO_MAX_IMAGE_PIXELS) throws.
    return failed("cannot decode image (" + e.err + ")");
  }
  return true;
}

}  // namespace conversion
}  // namespace hybrid_vo
