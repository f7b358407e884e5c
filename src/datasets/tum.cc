// TUM RGB-D reader (see readers.h for the layout and the association).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/datasets/text_file.h"

namespace hybrid_vo {
namespace datasets {
namespace {

namespace fs = std::filesystem;

struct GtSample {
  double time = 0.0;
  Eigen::Vector3d c_w = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_wc = Eigen::Quaterniond::Identity();
};

bool read_camera(const std::string& path, CameraModel* camera, std::string* error) {
  std::vector<std::string> lines;
  if (!read_lines(path, &lines, error)) return false;
  std::map<std::string, double> values;
  static const char* const kKeys[] = {"fx", "fy", "cx", "cy", "k1", "k2",
                                      "p1", "p2", "k3", "width", "height"};
  for (size_t k = 0; k < lines.size(); ++k) {
    if (is_blank_or_comment(lines[k])) continue;
    const int line = static_cast<int>(k + 1);
    const std::vector<std::string> fields = split_fields(lines[k]);
    if (!expect_field_count(fields, 2, "key value", path, line, error)) return false;
    const std::string& key = fields[0];
    if (std::find(std::begin(kKeys), std::end(kKeys), key) == std::end(kKeys))
      return fail(error, located(path, line,
                                 "unknown key '" + key +
                                     "' (known: fx fy cx cy k1 k2 p1 p2 k3 width height)"));
    if (values.count(key)) return fail(error, located(path, line, "repeated key '" + key + "'"));
    double value = 0.0;
    if (key == "width" || key == "height") {
      int size = 0;
      if (!parse_int(fields[1], &size) || size < 0)
        return fail(error, located(path, line,
                                   key + " '" + fields[1] + "' is not a non-negative integer"));
      value = size;
    } else if (!parse_fields(fields, 1, 1, path, line, &value, error)) {
      return false;
    }
    values[key] = value;
  }
  for (const char* key : {"fx", "fy", "cx", "cy"})
    if (!values.count(key)) return fail(error, located(path, 0, std::string("no '") + key + "'"));
  if (!(values["fx"] > 0.0) || !(values["fy"] > 0.0))
    return fail(error, located(path, 0, "fx and fy must be positive"));
  camera->pinhole = PinholeCamera(values["fx"], values["fy"], values["cx"], values["cy"],
                                  static_cast<int>(values["width"]),
                                  static_cast<int>(values["height"]));
  camera->distortion = {values["k1"], values["k2"], values["p1"], values["p2"], values["k3"]};
  return true;
}

bool read_ground_truth(const std::string& path, std::vector<GtSample>* samples,
                       std::string* error) {
  std::vector<std::string> lines;
  if (!read_lines(path, &lines, error)) return false;
  samples->clear();
  for (size_t k = 0; k < lines.size(); ++k) {
    if (is_blank_or_comment(lines[k])) continue;
    const int line = static_cast<int>(k + 1);
    const std::vector<std::string> fields = split_fields(lines[k]);
    double v[8];
    if (!expect_field_count(fields, 8, "timestamp tx ty tz qx qy qz qw", path, line, error) ||
        !parse_fields(fields, 0, 8, path, line, v, error))
      return false;
    GtSample sample;
    sample.time = v[0];
    sample.c_w = Eigen::Vector3d(v[1], v[2], v[3]);
    sample.q_wc = Eigen::Quaterniond(v[7], v[4], v[5], v[6]);  // stored x y z w
    // Written to 4 or more digits, so a unit quaternion's norm is within ~1e-4 of 1.
    const double norm = sample.q_wc.norm();
    if (std::abs(norm - 1.0) > 1e-2)
      return fail(error, located(path, line,
                                 "quaternion (qx qy qz qw) has norm " + std::to_string(norm) +
                                     ", not 1"));
    sample.q_wc.normalize();
    samples->push_back(sample);
  }
  if (samples->empty()) return fail(error, located(path, 0, "no ground-truth samples"));
  std::stable_sort(samples->begin(), samples->end(),
                   [](const GtSample& a, const GtSample& b) { return a.time < b.time; });
  return true;
}

// The ground-truth pose at `time`, or false when no sample is close enough.
bool pose_at(const std::vector<GtSample>& samples, double time, const TumOptions& options,
             Eigen::Matrix3d* R_wc, Eigen::Vector3d* c_w) {
  const auto after = std::lower_bound(
      samples.begin(), samples.end(), time,
      [](const GtSample& sample, double t) { return sample.time < t; });
  const GtSample* next = after == samples.end() ? nullptr : &*after;
  const GtSample* previous = after == samples.begin() ? nullptr : &*(after - 1);
  const GtSample* nearest = next;
  if (!nearest || (previous && time - previous->time < next->time - time)) nearest = previous;
  if (!(std::abs(nearest->time - time) <= options.max_time_difference)) return false;
  if (options.interpolate && previous && next && next->time > previous->time &&
      next->time - previous->time <= options.max_interpolation_gap) {
    const double alpha = (time - previous->time) / (next->time - previous->time);
    *c_w = (1.0 - alpha) * previous->c_w + alpha * next->c_w;
    // Eigen's slerp takes the shorter arc, so the q / -q sign flips of the files are harmless.
    *R_wc = previous->q_wc.slerp(alpha, next->q_wc).toRotationMatrix();
  } else {
    *c_w = nearest->c_w;
    *R_wc = nearest->q_wc.toRotationMatrix();
  }
  return true;
}

}  // namespace

bool read_tum(const std::string& path, Sequence* sequence, std::string* error,
              const TumOptions& options) {
  fs::path dir = fs::path(path).lexically_normal();
  if (dir.has_parent_path() && dir.filename().empty()) dir = dir.parent_path();  // trailing '/'
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(error, located(path, 0, "no such directory"));
  const std::string rgb_path = (dir / "rgb.txt").string();
  const std::string gt_path = (dir / "groundtruth.txt").string();
  const std::string camera_path = (dir / "camera.txt").string();

  CameraModel camera;
  if (!read_camera(camera_path, &camera, error)) return false;
  std::vector<GtSample> samples;
  if (!read_ground_truth(gt_path, &samples, error)) return false;

  std::vector<std::string> lines;
  if (!read_lines(rgb_path, &lines, error)) return false;
  sequence->name = dir.filename().string();
  sequence->format = "tum";
  sequence->frames.clear();
  sequence->skipped_frames = 0;
  for (size_t k = 0; k < lines.size(); ++k) {
    if (is_blank_or_comment(lines[k])) continue;
    const int line = static_cast<int>(k + 1);
    const std::vector<std::string> fields = split_fields(lines[k]);
    Frame frame;
    if (!expect_field_count(fields, 2, "timestamp image", rgb_path, line, error) ||
        !parse_fields(fields, 0, 1, rgb_path, line, &frame.timestamp, error))
      return false;
    if (!pose_at(samples, frame.timestamp, options, &frame.R_wc, &frame.c_w)) {
      ++sequence->skipped_frames;
      continue;
    }
    frame.image_path = (dir / fields[1]).string();
    if (!fs::is_regular_file(frame.image_path, ec))
      return fail(error, located(rgb_path, line, "no such image " + frame.image_path));
    frame.camera = camera;
    sequence->frames.push_back(frame);
  }
  if (sequence->frames.empty())
    return fail(error, located(rgb_path, 0,
                               "no image has ground truth within " +
                                   std::to_string(options.max_time_difference) + " s in " +
                                   gt_path));
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
