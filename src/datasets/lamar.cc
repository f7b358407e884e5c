// LaMAR Capture session reader (see lamar.h for the format and its conventions).
#include "hybrid_vo/datasets/lamar.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "hybrid_vo/datasets/text_file.h"

namespace hybrid_vo {
namespace datasets {
namespace {

namespace fs = std::filesystem;

struct CsvRow {
  int line = 0;
  std::vector<std::string> fields;
};

// The data lines of a LaMAR CSV file (no comments, no blank lines), split into fields.
bool read_csv(const std::string& path, std::vector<CsvRow>* rows, std::string* error) {
  std::vector<std::string> lines;
  if (!read_lines(path, &lines, error)) return false;
  rows->clear();
  for (size_t k = 0; k < lines.size(); ++k)
    if (!is_blank_or_comment(lines[k]))
      rows->push_back({static_cast<int>(k + 1), split_csv(lines[k])});
  return true;
}

bool parse_timestamp(const std::string& token, const std::string& path, int line, int64_t* us,
                     std::string* error) {
  if (!parse_int64(token, us) || *us < 0)
    return fail(error, located(path, line,
                               "timestamp '" + token + "' is not a non-negative integer (us)"));
  return true;
}

// qw, qx, qy, qz, tx, ty, tz from fields[first, first + 7): X_to = R X_from + t.
bool parse_pose(const std::vector<std::string>& fields, size_t first, const std::string& path,
                int line, Eigen::Isometry3d* T, std::string* error) {
  double v[7];
  if (!parse_fields(fields, first, 7, path, line, v, error)) return false;
  const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
  // Written with full precision by scantools; 1e-3 leaves room for hand-rounded files.
  if (!(std::abs(q.norm() - 1.0) < 1e-3)) {
    std::ostringstream message;
    message << "quaternion (qw, qx, qy, qz) has norm " << q.norm() << ", not 1";
    return fail(error, located(path, line, message.str()));
  }
  T->setIdentity();
  T->linear() = q.normalized().toRotationMatrix();
  T->translation() = Eigen::Vector3d(v[4], v[5], v[6]);
  return true;
}

// COLMAP's parameter count of each model (scantools CAMERA_MODEL_PARAM_NAMES); -1 if unknown.
int model_parameter_count(const std::string& model) {
  static const std::map<std::string, int> kCounts = {
      {"SIMPLE_PINHOLE", 3}, {"PINHOLE", 4},         {"SIMPLE_RADIAL", 4},
      {"RADIAL", 5},         {"OPENCV", 8},          {"OPENCV_FISHEYE", 8},
      {"FULL_OPENCV", 12},   {"FOV", 5},             {"SIMPLE_RADIAL_FISHEYE", 4},
      {"RADIAL_FISHEYE", 5}, {"THIN_PRISM_FISHEYE", 12}};
  const auto it = kCounts.find(model);
  return it == kCounts.end() ? -1 : it->second;
}

// camera_info terms of a COLMAP model; false (with the reason) for models ROS cannot express.
bool to_intrinsics(const std::string& model, const std::vector<double>& p, CameraIntrinsics* c,
                   std::string* unsupported) {
  const bool single_focal =
      model == "SIMPLE_PINHOLE" || model == "SIMPLE_RADIAL" || model == "RADIAL";
  const bool plumb_bob = single_focal || model == "PINHOLE" || model == "OPENCV";
  if (!plumb_bob && model != "FULL_OPENCV" && model != "OPENCV_FISHEYE") {
    *unsupported = "camera model " + model + " has no camera_info equivalent";
    return false;
  }
  const size_t k = single_focal ? 3 : 4;  // the first distortion parameter
  c->fx = p[0];
  c->fy = single_focal ? p[0] : p[1];
  c->cx = p[k - 2] - 0.5;  // COLMAP's pixel centres are at +0.5
  c->cy = p[k - 1] - 0.5;
  const std::vector<double> rest(p.begin() + k, p.end());
  if (plumb_bob) {
    c->distortion_model = "plumb_bob";
    c->D.assign(5, 0.0);
    std::copy(rest.begin(), rest.end(), c->D.begin());  // k1 [k2 [p1 p2]]
  } else {
    // FULL_OPENCV: k1 k2 p1 p2 k3 k4 k5 k6; OPENCV_FISHEYE: k1 k2 k3 k4. Both in ROS's order.
    c->distortion_model = model == "FULL_OPENCV" ? "rational_polynomial" : "equidistant";
    c->D = rest;
  }
  if (!(c->fx > 0.0) || !(c->fy > 0.0)) {
    *unsupported = "non-positive focal length";
    return false;
  }
  return true;
}

bool read_sensors(const std::string& path, LamarSession* s, std::string* error) {
  std::vector<CsvRow> rows;
  if (!read_csv(path, &rows, error)) return false;
  std::set<std::string> ids;
  for (const CsvRow& row : rows) {
    const std::vector<std::string>& f = row.fields;
    if (f.size() < 3)
      return fail(error, located(path, row.line,
                                 "expected sensor_id, name, sensor_type[, params], found " +
                                     std::to_string(f.size()) + " fields"));
    LamarSensor sensor;
    sensor.id = f[0];
    sensor.name = f[1];
    sensor.type = f[2];
    sensor.line = row.line;
    if (sensor.id.empty()) return fail(error, located(path, row.line, "empty sensor_id"));
    if (!ids.insert(sensor.id).second)
      return fail(error, located(path, row.line, "duplicate sensor '" + sensor.id + "'"));
    if (sensor.is_camera()) {
      if (f.size() < 6)
        return fail(error, located(path, row.line,
                                   "a camera needs model, width, height and parameters"));
      sensor.model = f[3];
      const int count = model_parameter_count(sensor.model);
      if (count >= 0 && f.size() != 6 + static_cast<size_t>(count))
        return fail(error, located(path, row.line,
                                   "camera model " + sensor.model + " takes " +
                                       std::to_string(count) + " parameters, found " +
                                       std::to_string(f.size() - 6)));
      CameraIntrinsics& c = sensor.intrinsics;
      if (!parse_int(f[4], &c.width) || !parse_int(f[5], &c.height) || c.width <= 0 ||
          c.height <= 0)
        return fail(error, located(path, row.line,
                                   "image size '" + f[4] + " x " + f[5] +
                                       "' is not two positive integers"));
      std::vector<double> params(f.size() - 6);
      if (!parse_fields(f, 6, params.size(), path, row.line, params.data(), error)) return false;
      if (count < 0)
        sensor.unsupported = "unknown camera model '" + sensor.model + "'";
      else
        to_intrinsics(sensor.model, params, &c, &sensor.unsupported);
    }
    s->sensors.push_back(sensor);
  }
  return true;
}

bool read_rigs(const std::string& path, LamarSession* s, std::string* error) {
  std::vector<CsvRow> rows;
  if (!read_csv(path, &rows, error)) return false;
  for (const CsvRow& row : rows) {
    const std::vector<std::string>& f = row.fields;
    if (!expect_field_count(f, 9, "rig_id, sensor_id, qw, qx, qy, qz, tx, ty, tz", path, row.line,
                            error))
      return false;
    if (s->sensor(f[0]))
      return fail(error, located(path, row.line, "rig id '" + f[0] + "' is also a sensor id"));
    if (!s->sensor(f[1]))
      return fail(error, located(path, row.line, "unknown sensor '" + f[1] + "'"));
    Eigen::Isometry3d T_rig_sensor;
    if (!parse_pose(f, 2, path, row.line, &T_rig_sensor, error)) return false;
    if (!s->rigs[f[0]].emplace(f[1], T_rig_sensor).second)
      return fail(error, located(path, row.line,
                                 "sensor '" + f[1] + "' is listed twice in rig '" + f[0] + "'"));
  }
  return true;
}

bool read_trajectories(const std::string& path, LamarSession* s, std::string* error) {
  std::vector<CsvRow> rows;
  if (!read_csv(path, &rows, error)) return false;
  for (const CsvRow& row : rows) {
    const std::vector<std::string>& f = row.fields;
    // The optional 6x6 covariance is not used, so its values are not checked.
    if (f.size() != 9 && f.size() != 45)
      return fail(error, located(path, row.line,
                                 "expected 9 fields (timestamp, device_id, qw, qx, qy, qz, tx, "
                                 "ty, tz) or 45 (with a covariance), found " +
                                     std::to_string(f.size())));
    int64_t us = 0;
    if (!parse_timestamp(f[0], path, row.line, &us, error)) return false;
    if (!s->sensor(f[1]) && !s->rigs.count(f[1]))
      return fail(error, located(path, row.line, "unknown device '" + f[1] + "'"));
    Eigen::Isometry3d T_world_device;
    if (!parse_pose(f, 2, path, row.line, &T_world_device, error)) return false;
    if (!s->poses.emplace(std::make_pair(us, f[1]), T_world_device).second)
      return fail(error, located(path, row.line,
                                 "second pose of '" + f[1] + "' at " + f[0]));
  }
  s->poses_path = path;
  return true;
}

bool read_images(const std::string& path, LamarSession* s, std::string* error) {
  std::vector<CsvRow> rows;
  if (!read_csv(path, &rows, error)) return false;
  std::set<std::pair<int64_t, std::string>> seen;
  const fs::path raw_data = fs::path(s->dir) / "raw_data";
  for (const CsvRow& row : rows) {
    const std::vector<std::string>& f = row.fields;
    if (!expect_field_count(f, 3, "timestamp, sensor_id, image_path", path, row.line, error))
      return false;
    LamarImage image;
    image.line = row.line;
    image.sensor_id = f[1];
    if (!parse_timestamp(f[0], path, row.line, &image.timestamp_us, error)) return false;
    const LamarSensor* sensor = s->sensor(f[1]);
    if (!sensor) return fail(error, located(path, row.line, "unknown sensor '" + f[1] + "'"));
    if (!sensor->is_camera())
      return fail(error, located(path, row.line,
                                 "sensor '" + f[1] + "' is a " + sensor->type + ", not a camera"));
    if (!seen.insert({image.timestamp_us, f[1]}).second)
      return fail(error, located(path, row.line,
                                 "second image of '" + f[1] + "' at " + f[0]));
    image.path = (raw_data / f[2]).string();
    std::error_code ec;
    if (f[2].empty() || !fs::is_regular_file(image.path, ec))
      return fail(error, located(path, row.line, "no such image " + image.path));
    s->images.push_back(image);
  }
  std::stable_sort(s->images.begin(), s->images.end(),
                   [](const LamarImage& a, const LamarImage& b) {
                     return a.timestamp_us < b.timestamp_us;
                   });
  return true;
}

}  // namespace

const LamarSensor* LamarSession::sensor(const std::string& id) const {
  for (const LamarSensor& s : sensors)
    if (s.id == id) return &s;
  return nullptr;
}

bool LamarSession::rig_of(const std::string& sensor_id, std::string* rig_id,
                          Eigen::Isometry3d* T_rig_sensor) const {
  for (const auto& [rig, members] : rigs) {
    const auto it = members.find(sensor_id);
    if (it == members.end()) continue;
    *rig_id = rig;
    *T_rig_sensor = it->second;
    return true;
  }
  return false;
}

bool LamarSession::camera_pose(int64_t timestamp_us, const std::string& sensor_id,
                               Eigen::Isometry3d* T_world_camera) const {
  const auto own = poses.find({timestamp_us, sensor_id});
  if (own != poses.end()) {
    *T_world_camera = own->second;
    return true;
  }
  for (const auto& [rig, members] : rigs) {
    const auto member = members.find(sensor_id);
    const auto rig_pose = poses.find({timestamp_us, rig});
    if (member == members.end() || rig_pose == poses.end()) continue;
    *T_world_camera = rig_pose->second * member->second;
    return true;
  }
  return false;
}

bool read_lamar_session(const std::string& dir, LamarSession* session, std::string* error) {
  *session = LamarSession();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(error, located(dir, 0, "no such directory"));
  session->dir = dir;
  session->sensors_path = (fs::path(dir) / "sensors.txt").string();
  session->images_path = (fs::path(dir) / "images.txt").string();
  const std::string rigs_path = (fs::path(dir) / "rigs.txt").string();
  const std::string alignment_path =
      (fs::path(dir) / "proc" / "alignment_trajectories.txt").string();
  const std::string trajectories_path = (fs::path(dir) / "trajectories.txt").string();

  if (!read_sensors(session->sensors_path, session, error)) return false;
  if (fs::exists(rigs_path, ec) && !read_rigs(rigs_path, session, error)) return false;
  const std::string poses_path = fs::exists(alignment_path, ec)      ? alignment_path
                                 : fs::exists(trajectories_path, ec) ? trajectories_path
                                                                     : "";
  if (!poses_path.empty() && !read_trajectories(poses_path, session, error)) return false;
  if (!read_images(session->images_path, session, error)) return false;
  if (session->images.empty())
    return fail(error, located(session->images_path, 0, "no images"));
  return true;
}

std::vector<LamarStream> lamar_camera_streams(const LamarSession& session) {
  std::map<std::string, int> images_of;
  for (const LamarImage& image : session.images) ++images_of[image.sensor_id];
  std::vector<LamarStream> streams;
  std::map<std::string, size_t> index_of;  // stream id -> index in streams
  std::map<std::string, size_t> rank;      // stream id -> first sensor's line
  for (size_t i = 0; i < session.images.size(); ++i) {
    const LamarImage& image = session.images[i];
    std::string id = image.sensor_id;
    const std::string suffix = "_" + std::to_string(image.timestamp_us);
    if (images_of[id] == 1 && id.size() > suffix.size() &&
        id.compare(id.size() - suffix.size(), suffix.size(), suffix) == 0)
      id.resize(id.size() - suffix.size());  // a phone's per-frame camera
    const auto [it, added] = index_of.emplace(id, streams.size());
    if (added) streams.push_back({id, {}});
    streams[it->second].images.push_back(i);
    const size_t line = session.sensor(image.sensor_id)->line;
    rank[id] = added ? line : std::min(rank[id], line);
  }
  std::stable_sort(streams.begin(), streams.end(),
                   [&](const LamarStream& a, const LamarStream& b) {
                     return rank[a.id] < rank[b.id];
                   });
  return streams;
}

}  // namespace datasets
}  // namespace hybrid_vo
