// KITTI odometry: the files of the layout (kitti.h) and the sequence reader (readers.h).
#include "hybrid_vo/datasets/kitti.h"

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/datasets/text_file.h"

namespace hybrid_vo {
namespace datasets {
namespace {

namespace fs = std::filesystem;

// The lines of a file with one record per line and no comments: line k is frame k, so a blank
// line inside would shift every later frame and is an error; trailing blank lines are dropped.
bool read_records(const std::string& path, std::vector<std::string>* records,
                  std::string* error) {
  if (!read_lines(path, records, error)) return false;
  while (!records->empty() && split_fields(records->back()).empty()) records->pop_back();
  for (size_t k = 0; k < records->size(); ++k)
    if (split_fields((*records)[k]).empty())
      return fail(error, located(path, static_cast<int>(k + 1), "empty line"));
  if (records->empty()) return fail(error, located(path, 0, "empty file"));
  return true;
}

bool parse_projection(const std::vector<std::string>& fields, const std::string& path, int line,
                      KittiProjection* out, std::string* error) {
  if (!expect_field_count(fields, 13, fields[0] + " and 12 numbers of the 3x4 matrix", path, line,
                          error))
    return false;
  double p[12];
  if (!parse_fields(fields, 1, 12, path, line, p, error)) return false;
  for (int k = 0; k < 12; ++k) out->P(k / 4, k % 4) = p[k];
  if (!pinhole_from_matrix(out->P.leftCols<3>(), path, line, &out->camera, error)) return false;
  out->line = line;
  return true;
}

// Finds the sequence folder and the odometry root from either of the accepted paths.
bool resolve_paths(const std::string& path, fs::path* sequence_dir, fs::path* root,
                   std::string* error) {
  fs::path p = fs::path(path).lexically_normal();
  if (p.has_parent_path() && p.filename().empty()) p = p.parent_path();  // trailing '/'
  std::error_code ec;
  if (!fs::is_directory(p, ec)) return fail(error, located(path, 0, "no such directory"));
  if (fs::is_directory(p / "sequences", ec)) {
    std::vector<fs::path> sequences;
    for (const auto& entry : fs::directory_iterator(p / "sequences", ec))
      if (entry.is_directory()) sequences.push_back(entry.path());
    if (sequences.size() != 1) {
      std::string names;
      for (const fs::path& s : sequences) names += " " + s.filename().string();
      return fail(error, located((p / "sequences").string(), 0,
                                 std::to_string(sequences.size()) + " sequences (" +
                                     (names.empty() ? std::string(" none") : names) +
                                     " ); pass <root>/sequences/<name>"));
    }
    *sequence_dir = sequences.front();
    *root = p;
    return true;
  }
  *sequence_dir = p;
  *root = (p / ".." / "..").lexically_normal();
  return true;
}

}  // namespace

double KittiCalibration::baseline() const {
  if (!P1.present()) return 0.0;
  return -P1.P(0, 3) / P1.camera.fx;
}

bool read_kitti_calibration(const std::string& path, KittiCalibration* calibration,
                            std::string* error) {
  std::vector<std::string> lines;
  if (!read_lines(path, &lines, error)) return false;
  *calibration = KittiCalibration();
  for (size_t k = 0; k < lines.size(); ++k) {
    const std::vector<std::string> fields = split_fields(lines[k]);
    if (fields.empty()) continue;
    KittiProjection* target = fields[0] == "P0:"   ? &calibration->P0
                              : fields[0] == "P1:" ? &calibration->P1
                                                   : nullptr;
    if (!target || target->present()) continue;  // the first P0 / P1 counts
    if (!parse_projection(fields, path, static_cast<int>(k + 1), target, error)) return false;
  }
  if (!calibration->P0.present()) return fail(error, located(path, 0, "no 'P0:' line"));
  const KittiProjection& P1 = calibration->P1;
  if (P1.present()) {
    // The right camera of the rectified pair: P1 = K [I | (-b, 0, 0)].
    if (P1.P(1, 3) != 0.0 || P1.P(2, 3) != 0.0)
      return fail(error, located(path, P1.line,
                                 "P1 is not a rectified right camera (P1(1,3) and P1(2,3) "
                                 "must be 0)"));
    if (!(calibration->baseline() > 0.0))
      return fail(error, located(path, P1.line,
                                 "P1(0,3) = " + std::to_string(P1.P(0, 3)) +
                                     " gives no positive baseline (expected -fx * b)"));
  }
  return true;
}

bool read_kitti_times(const std::string& path, std::vector<double>* times, std::string* error) {
  std::vector<std::string> records;
  if (!read_records(path, &records, error)) return false;
  times->assign(records.size(), 0.0);
  for (size_t k = 0; k < records.size(); ++k) {
    const int line = static_cast<int>(k + 1);
    const std::vector<std::string> fields = split_fields(records[k]);
    if (!expect_field_count(fields, 1, "timestamp", path, line, error) ||
        !parse_fields(fields, 0, 1, path, line, &(*times)[k], error))
      return false;
    if (k > 0 && !((*times)[k] > (*times)[k - 1]))
      return fail(error, located(path, line, "timestamp " + fields[0] +
                                                 " does not increase on the previous line's"));
  }
  return true;
}

bool read_kitti_poses(const std::string& path, std::vector<KittiPose>* poses,
                      std::string* error) {
  std::vector<std::string> records;
  if (!read_records(path, &records, error)) return false;
  poses->assign(records.size(), KittiPose());
  for (size_t k = 0; k < records.size(); ++k) {
    const int line = static_cast<int>(k + 1);
    const std::vector<std::string> fields = split_fields(records[k]);
    double p[12];
    if (!expect_field_count(fields, 12, "row-major 3x4 camera-to-world [R | t]", path, line,
                            error) ||
        !parse_fields(fields, 0, 12, path, line, p, error))
      return false;
    Eigen::Matrix3d R;
    R << p[0], p[1], p[2], p[4], p[5], p[6], p[8], p[9], p[10];
    if (!to_rotation(R, path, line, &(*poses)[k].R_wc, error)) return false;
    (*poses)[k].c_w = Eigen::Vector3d(p[3], p[7], p[11]);
  }
  return true;
}

std::string kitti_image_path(const std::string& sequence_dir, int camera, size_t frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu.png", frame);
  return (fs::path(sequence_dir) / ("image_" + std::to_string(camera)) / name).string();
}

int count_kitti_images(const std::string& sequence_dir, int camera) {
  const fs::path dir = fs::path(sequence_dir) / ("image_" + std::to_string(camera));
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return -1;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file()) ++count;
  return count;
}

bool read_kitti(const std::string& path, Sequence* sequence, std::string* error) {
  fs::path sequence_dir, root;
  if (!resolve_paths(path, &sequence_dir, &root, error)) return false;
  const std::string name = sequence_dir.filename().string();
  const std::string times_path = (sequence_dir / "times.txt").string();
  const std::string poses_path = (root / "poses" / (name + ".txt")).string();

  KittiCalibration calibration;
  std::vector<double> times;
  std::vector<KittiPose> poses;
  if (!read_kitti_calibration((sequence_dir / "calib.txt").string(), &calibration, error) ||
      !read_kitti_times(times_path, &times, error) ||
      !read_kitti_poses(poses_path, &poses, error))
    return false;
  if (times.size() != poses.size())
    return fail(error, located(poses_path, 0,
                               std::to_string(poses.size()) + " poses for " +
                                   std::to_string(times.size()) + " frames in " + times_path));

  sequence->name = name;
  sequence->format = "kitti";
  sequence->skipped_frames = 0;
  sequence->frames.assign(times.size(), Frame());
  for (size_t k = 0; k < times.size(); ++k) {
    Frame& frame = sequence->frames[k];
    frame.timestamp = times[k];
    frame.R_wc = poses[k].R_wc;
    frame.c_w = poses[k].c_w;
    frame.image_path = kitti_image_path(sequence_dir.string(), 0, k);
    std::error_code ec;
    if (!fs::is_regular_file(frame.image_path, ec))
      return fail(error, located(frame.image_path, 0,
                                 "no such image (frame " + std::to_string(k) + " of " +
                                     poses_path + ")"));
  }

  // All images of a KITTI sequence share the size of the first.
  const cv::Mat first = cv::imread(sequence->frames.front().image_path, cv::IMREAD_UNCHANGED);
  if (first.empty())
    return fail(error, located(sequence->frames.front().image_path, 0, "cannot decode image"));
  CameraModel camera;
  camera.pinhole = calibration.P0.camera;
  camera.pinhole.width = first.cols;
  camera.pinhole.height = first.rows;
  for (Frame& frame : sequence->frames) frame.camera = camera;
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
