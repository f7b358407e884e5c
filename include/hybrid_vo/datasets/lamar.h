#pragma once

// Reader of a LaMAR Capture session (microsoft/lamar-benchmark: CAPTURE.md, scantools/capture),
// without ROS: sessions/<id>/{sensors.txt, rigs.txt, trajectories.txt, images.txt, raw_data/,
// proc/alignment_trajectories.txt}.
//
// Every file is CSV: fields separated by ',' (LaMAR writes ", "), '#' comment lines (the first
// names the columns), blank lines ignored. Timestamps are integers, microseconds.
//   sensors.txt       sensor_id, name, sensor_type, [sensor_params]+
//                     A "camera" has the params model, width, height, then COLMAP's parameters:
//                       SIMPLE_PINHOLE f cx cy           PINHOLE fx fy cx cy
//                       SIMPLE_RADIAL f cx cy k          RADIAL f cx cy k1 k2
//                       OPENCV fx fy cx cy k1 k2 p1 p2   OPENCV_FISHEYE fx fy cx cy k1 k2 k3 k4
//                       FULL_OPENCV fx fy cx cy k1 k2 p1 p2 k3 k4 k5 k6
//                     Other sensor types (depth, wifi, bluetooth, ...) are kept by id and type.
//   rigs.txt          rig_id, sensor_id, qw, qx, qy, qz, tx, ty, tz: sensor-to-rig,
//                     X_rig = R X_sensor + t.
//   trajectories.txt  timestamp, device_id, qw, qx, qy, qz, tx, ty, tz[, 36 covariances]:
//                     device-to-world, X_world = R X_device + t, for a rig or a sensor.
//   images.txt        timestamp, sensor_id, image_path (relative to raw_data/)
// Kapture, which the format follows otherwise, stores world-to-device poses; LaMAR reverses both
// rigs and trajectories (CAPTURE.md; Session.get_pose composes T_rig2world * T_sensor2rig).
// Quaternions are Hamilton, scalar first (scantools Pose.from_list: qw, qx, qy, qz).
// Ground truth: proc/alignment_trajectories.txt (the same format, in the global reference) when
// it exists, else trajectories.txt; neither is required (query sessions have none).
//
// Principal points are COLMAP's: the image's top-left corner is (0, 0), so pixel centres sit at
// +0.5 (LaMAR's rotate_camera maps cx to w - cx). CameraIntrinsics converts them to the OpenCV
// and ROS convention of pixel centres at integers: c = c_colmap - 0.5.
//
// Phone sessions (scantools/run_phone_to_capture.py): ARKit's intrinsics change per frame, so a
// phone session has one camera per image, "<prefix>_<timestamp>" (e.g. cam_phone_<timestamp>),
// posed by itself in trajectories.txt. Their images were already turned upright by np.rot90 with
// K and the pose turned to match, so the files are consistent as they are; LamarStream groups
// those per-frame cameras into one stream "<prefix>".

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

namespace hybrid_vo {
namespace datasets {

// A camera in the terms of ROS's camera_info, pixel centres at integers.
struct CameraIntrinsics {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::string distortion_model;  // "plumb_bob", "rational_polynomial" or "equidistant"
  std::vector<double> D;         // as sensor_msgs/CameraInfo orders them
};

struct LamarSensor {
  std::string id, name, type;
  int line = 0;  // in sensors.txt
  // Cameras only: the model as written, and its intrinsics when the model is supported (else
  // `unsupported` says why; an error only when the camera is converted).
  std::string model;
  CameraIntrinsics intrinsics;
  std::string unsupported;
  bool is_camera() const { return type == "camera"; }
};

struct LamarImage {
  int64_t timestamp_us = 0;
  std::string sensor_id;
  std::string path;  // <session>/raw_data/<image_path>
  int line = 0;      // in images.txt
};

struct LamarSession {
  std::string dir, sensors_path, images_path;
  std::vector<LamarSensor> sensors;  // in file order
  // rig id -> sensor id -> T_rig_sensor
  std::map<std::string, std::map<std::string, Eigen::Isometry3d>> rigs;
  // (timestamp, device id) -> T_world_device
  std::map<std::pair<int64_t, std::string>, Eigen::Isometry3d> poses;
  std::string poses_path;          // the file the poses came from; empty without poses
  std::vector<LamarImage> images;  // by timestamp, then file order

  const LamarSensor* sensor(const std::string& id) const;
  // The rig that holds `sensor_id` and its sensor-to-rig transform; false when in none.
  bool rig_of(const std::string& sensor_id, std::string* rig_id,
              Eigen::Isometry3d* T_rig_sensor) const;
  // The camera-to-world pose of `sensor_id` at `timestamp_us`: its own pose, else the pose of a
  // rig holding it composed with the sensor-to-rig transform. False when neither exists.
  bool camera_pose(int64_t timestamp_us, const std::string& sensor_id,
                   Eigen::Isometry3d* T_world_camera) const;
};

// Reads and checks the session folder `dir`: every error names the file and the line
// ("file:line: message"): a missing sensors.txt or images.txt, wrong field counts, non-numbers,
// NaN, a quaternion that is not of unit length, an unknown sensor, rig or device, a duplicate
// entry, an image file that does not exist. Images are not decoded.
bool read_lamar_session(const std::string& dir, LamarSession* session, std::string* error);

// The images of one camera, in time order. A per-frame camera of a phone session (see above)
// joins the stream named by its prefix.
struct LamarStream {
  std::string id;
  std::vector<size_t> images;  // indices into LamarSession::images
};
// The camera streams in the order of their (first) camera in sensors.txt.
std::vector<LamarStream> lamar_camera_streams(const LamarSession& session);

}  // namespace datasets
}  // namespace hybrid_vo
