#include "hybrid_vo/conversion/lamar_to_bag.h"

#include <algorithm>
#include <exception>
#include <map>
#include <set>
#include <sstream>

#include "hybrid_vo/conversion/bag_writing.h"
#include "hybrid_vo/datasets/lamar.h"
#include "hybrid_vo/datasets/text_file.h"
#include "hybrid_vo/render/camera_path.h"

namespace hybrid_vo {
namespace conversion {
namespace {

using datasets::fail;
using datasets::located;
using datasets::LamarSession;
using datasets::LamarStream;

std::vector<std::string> split_ids(const std::string& list) {
  std::vector<std::string> ids;
  for (const std::string& id : datasets::split_csv(list))
    if (!id.empty()) ids.push_back(id);
  return ids;
}

// The streams named in options.cameras (all when empty), in that order.
bool select_streams(const LamarSession& session, const std::vector<std::string>& wanted,
                    std::vector<LamarStream>* selected, std::string* error) {
  const std::vector<LamarStream> streams = datasets::lamar_camera_streams(session);
  if (wanted.empty()) {
    *selected = streams;
    return true;
  }
  std::string known;
  for (const LamarStream& s : streams) known += (known.empty() ? "" : ", ") + s.id;
  for (const std::string& id : wanted) {
    const auto it = std::find_if(streams.begin(), streams.end(),
                                 [&](const LamarStream& s) { return s.id == id; });
    if (it == streams.end())
      return fail(error, located(session.images_path, 0,
                                 "no images of camera '" + id + "' (cameras: " + known + ")"));
    if (std::any_of(selected->begin(), selected->end(),
                    [&](const LamarStream& s) { return s.id == id; }))
      return fail(error, "--cameras names '" + id + "' twice");
    selected->push_back(*it);
  }
  return true;
}

// base_link -> each stream's optical frame: the first stream looks along base x (REP 103); a
// stream of a single camera in the same rig as the first follows through the rig. Others have
// no static transform (e.g. a phone, whose per-frame cameras are in no rig).
std::vector<geometry_msgs::TransformStamped> static_transforms(
    const LamarSession& session, const std::vector<LamarStream>& streams,
    const std::vector<std::string>& frames, const ros::Time& stamp) {
  Eigen::Isometry3d T_base_first = Eigen::Isometry3d::Identity();
  T_base_first.linear() = render::base_from_optical();
  std::vector<geometry_msgs::TransformStamped> transforms = {stamped(
      kBaseFrame, frames[0], stamp,
      to_transform(T_base_first.linear(), T_base_first.translation()))};
  const std::string first_sensor = session.images[streams[0].images[0]].sensor_id;
  std::string first_rig;
  Eigen::Isometry3d T_rig_first;
  if (!session.rig_of(first_sensor, &first_rig, &T_rig_first)) return transforms;
  for (size_t k = 1; k < streams.size(); ++k) {
    std::string rig;
    Eigen::Isometry3d T_rig_other;
    const std::string sensor = session.images[streams[k].images[0]].sensor_id;
    if (streams[k].id != sensor || !session.rig_of(sensor, &rig, &T_rig_other) ||
        rig != first_rig)
      continue;
    const Eigen::Isometry3d T_base_other = T_base_first * T_rig_first.inverse() * T_rig_other;
    transforms.push_back(stamped(kBaseFrame, frames[k], stamp,
                                 to_transform(T_base_other.linear(), T_base_other.translation())));
  }
  return transforms;
}

ros::Time stamp_of(int64_t timestamp_us, int64_t offset_ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(timestamp_us * 1000 + offset_ns));
  return t;
}

}  // namespace

std::string lamar_usage(const std::string& program) {
  std::ostringstream s;
  s << "Usage: " << program << " --session DIR --out OUT.bag [options]\n"
    << "Converts a LaMAR Capture session (DIR = sessions/<id> with sensors.txt, images.txt,\n"
    << "raw_data/, optionally rigs.txt, trajectories.txt, proc/alignment_trajectories.txt) into\n"
    << "a bag: /camera/<camera>/{image_raw,camera_info} per camera, /tf_static, and for the\n"
    << "first camera /ground_truth/pose and /tf world -> gt_camera_<camera>_optical.\n"
    << "  --cameras IDS     comma-separated camera ids, the first drives the node (default: all,\n"
    << "                    in sensors.txt order); a phone's per-frame cameras <id>_<timestamp>\n"
    << "                    are the one camera <id>\n"
    << "  --time-offset S   seconds added to the timestamps (default: 1 when the session's\n"
    << "                    timestamps start below 1 s, else 0)\n"
    << "  --compressed png|jpeg  images as sensor_msgs/CompressedImage on .../image_raw/compressed\n"
    << "                    (as robots record them) instead of raw on .../image_raw\n"
    << "  --jpeg-quality Q  with --compressed jpeg: quality 1..100 (default 95)\n";
  return s.str();
}

std::string parse_lamar_args(const std::vector<std::string>& args, LamarBagOptions* o) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      o->help = true;
      return "";
    }
    if (arg != "--session" && arg != "--out" && arg != "--cameras" && arg != "--time-offset" &&
        arg != "--compressed" && arg != "--jpeg-quality")
      return "unknown argument '" + arg + "'";
    if (i + 1 >= args.size() || args[i + 1].empty()) return arg + " needs a value";
    const std::string& v = args[++i];
    if (arg == "--session") o->session_dir = v;
    if (arg == "--out") o->out_bag = v;
    if (arg == "--cameras") {
      o->cameras = split_ids(v);
      if (o->cameras.empty()) return "--cameras needs at least one id";
    }
    if (arg == "--time-offset" &&
        (!datasets::parse_double(v, &o->time_offset) || o->time_offset < 0))
      return "bad value '" + v + "' for --time-offset (seconds, >= 0)";
    if (arg == "--compressed" && !parse_compressed_images(v, &o->images))
      return "bad value '" + v + "' for --compressed (png or jpeg)";
    if (arg == "--jpeg-quality" && !parse_jpeg_quality(v, &o->images))
      return "bad value '" + v + "' for --jpeg-quality (1..100)";
  }
  if (o->session_dir.empty()) return "--session DIR is required";
  if (o->out_bag.empty()) return "--out OUT.bag is required";
  return "";
}

bool convert_lamar(const LamarBagOptions& options, std::string* error, LamarBagSummary* summary) {
  LamarSession session;
  if (!datasets::read_lamar_session(options.session_dir, &session, error)) return false;
  std::vector<LamarStream> streams;
  if (!select_streams(session, options.cameras, &streams, error)) return false;

  // Names, and every camera of the selection must have camera_info intrinsics.
  std::vector<std::string> names, frames;
  std::map<size_t, size_t> stream_of;  // image index -> stream index
  int64_t first_us = -1;
  for (size_t k = 0; k < streams.size(); ++k) {
    names.push_back(sanitize_name(streams[k].id));
    frames.push_back(optical_frame(names.back()));
    if (std::count(names.begin(), names.end(), names.back()) > 1)
      return fail(error, "cameras '" + streams[k].id + "' and another one both become topic " +
                             camera_topic(names.back()) + "; select one with --cameras");
    for (size_t i : streams[k].images) {
      const datasets::LamarSensor* sensor = session.sensor(session.images[i].sensor_id);
      if (!sensor->unsupported.empty())
        return fail(error, located(session.sensors_path, sensor->line, sensor->unsupported));
      stream_of[i] = k;
      const int64_t us = session.images[i].timestamp_us;
      first_us = first_us < 0 ? us : std::min(first_us, us);
    }
  }
  const double offset_s =
      options.time_offset >= 0.0 ? options.time_offset : (first_us < 1000000 ? 1.0 : 0.0);
  const int64_t offset_ns = static_cast<int64_t>(offset_s * 1e9 + 0.5);
  if (first_us * 1000 + offset_ns <= 0)
    return fail(error, located(session.images_path, 0,
                               "the first stamp is 0, which a bag cannot hold: pass "
                               "--time-offset > 0"));

  BagOutput out;
  if (!out.open(options.out_bag, rosbag::compression::LZ4, error)) return false;
  out.set_image_format(options.images);
  LamarBagSummary result;
  result.images.assign(streams.size(), 0);
  result.poses_path = session.poses_path;
  result.time_offset = offset_s;
  try {
    const ros::Time t0 = stamp_of(first_us, offset_ns);
    out.write_tf_static(t0, static_transforms(session, streams, frames, t0),
                        "/hybrid_vo_lamar_to_bag");
    // session.images is in time order, so the bag is too.
    std::vector<int> first_channels(streams.size(), 0);
    for (const auto& [i, k] : stream_of) {
      const datasets::LamarImage& image = session.images[i];
      const datasets::LamarSensor& sensor = *session.sensor(image.sensor_id);
      const datasets::CameraIntrinsics& c = sensor.intrinsics;
      cv::Mat gray;
      int channels = 0;
      std::string why;
      if (!read_mono8(image.path, &gray, &channels, &why))
        return fail(error, located(session.images_path, image.line, why));
      // A phone's per-frame cameras may change size (sensors.txt says so), never their kind.
      if (first_channels[k] == 0) first_channels[k] = channels;
      if (channels != first_channels[k])
        return fail(error, located(session.images_path, image.line,
                                   image.path + ": " + std::to_string(channels) +
                                       "-channel image, the first of " + streams[k].id + " was " +
                                       std::to_string(first_channels[k]) + "-channel"));
      if (gray.cols != c.width || gray.rows != c.height)
        return fail(error, located(session.images_path, image.line,
                                   image.path + " is " + std::to_string(gray.cols) + "x" +
                                       std::to_string(gray.rows) + ", but " +
                                       located(session.sensors_path, sensor.line, "") +
                                       "says " + std::to_string(c.width) + "x" +
                                       std::to_string(c.height)));
      const ros::Time stamp = stamp_of(image.timestamp_us, offset_ns);
      const std::string topic = camera_topic(names[k]);
      out.write_image(topic + "/image_raw", frames[k], stamp, gray);
      const PinholeCamera K(c.fx, c.fy, c.cx, c.cy, c.width, c.height);
      out.bag().write(topic + "/camera_info", stamp,
                      make_camera_info(K, frames[k], stamp, 0.0, c.distortion_model, c.D));
      ++result.images[k];
      Eigen::Isometry3d T_world_camera;
      if (k == 0 && session.camera_pose(image.timestamp_us, image.sensor_id, &T_world_camera)) {
        out.write_ground_truth(ground_truth_frame(frames[0]), stamp, T_world_camera.linear(),
                               T_world_camera.translation());
        ++result.ground_truth;
      }
    }
    if (!out.commit(error)) return false;
  } catch (const std::exception& e) {
    // rosbag's, and any other (cv_bridge, allocation): the BagOutput still removes its file.
    return fail(error, located(options.out_bag, 0, e.what()));
  }
  for (size_t k = 0; k < streams.size(); ++k) {
    result.streams.push_back(streams[k].id);
    result.topics.push_back(camera_topic(names[k]));
  }
  if (summary) *summary = result;
  return true;
}

}  // namespace conversion
}  // namespace hybrid_vo
