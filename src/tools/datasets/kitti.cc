// KITTI odometry reader (see readers.h for the layout).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "datasets/readers.h"
#include "datasets/text_file.h"

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

bool read_kitti(const std::string& path, Sequence* sequence, std::string* error) {
  fs::path sequence_dir, root;
  if (!resolve_paths(path, &sequence_dir, &root, error)) return false;
  const std::string name = sequence_dir.filename().string();
  const std::string calib_path = (sequence_dir / "calib.txt").string();
  const std::string times_path = (sequence_dir / "times.txt").string();
  const std::string poses_path = (root / "poses" / (name + ".txt")).string();

  // P0 = K [I | 0] of the rectified left grayscale camera.
  std::vector<std::string> lines;
  if (!read_lines(calib_path, &lines, error)) return false;
  CameraModel camera;
  bool found_p0 = false;
  for (size_t k = 0; k < lines.size() && !found_p0; ++k) {
    const std::vector<std::string> fields = split_fields(lines[k]);
    if (fields.empty() || fields[0] != "P0:") continue;
    const int line = static_cast<int>(k + 1);
    if (!expect_field_count(fields, 13, "P0: and 12 numbers of the 3x4 matrix", calib_path, line,
                            error))
      return false;
    double p[12];
    if (!parse_fields(fields, 1, 12, calib_path, line, p, error)) return false;
    Eigen::Matrix3d K;
    K << p[0], p[1], p[2], p[4], p[5], p[6], p[8], p[9], p[10];
    if (!pinhole_from_matrix(K, calib_path, line, &camera.pinhole, error)) return false;
    found_p0 = true;
  }
  if (!found_p0) return fail(error, located(calib_path, 0, "no 'P0:' line"));

  std::vector<std::string> times, poses;
  if (!read_records(times_path, &times, error) || !read_records(poses_path, &poses, error))
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
    const int line = static_cast<int>(k + 1);
    Frame& frame = sequence->frames[k];
    const std::vector<std::string> time_fields = split_fields(times[k]);
    if (!expect_field_count(time_fields, 1, "timestamp", times_path, line, error) ||
        !parse_fields(time_fields, 0, 1, times_path, line, &frame.timestamp, error))
      return false;

    const std::vector<std::string> pose_fields = split_fields(poses[k]);
    double p[12];
    if (!expect_field_count(pose_fields, 12, "row-major 3x4 camera-to-world [R | t]", poses_path,
                            line, error) ||
        !parse_fields(pose_fields, 0, 12, poses_path, line, p, error))
      return false;
    Eigen::Matrix3d R;
    R << p[0], p[1], p[2], p[4], p[5], p[6], p[8], p[9], p[10];
    if (!to_rotation(R, poses_path, line, &frame.R_wc, error)) return false;
    frame.c_w = Eigen::Vector3d(p[3], p[7], p[11]);

    char image_name[32];
    std::snprintf(image_name, sizeof(image_name), "%06zu.png", k);
    frame.image_path = (sequence_dir / "image_0" / image_name).string();
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
  camera.pinhole.width = first.cols;
  camera.pinhole.height = first.rows;
  for (Frame& frame : sequence->frames) frame.camera = camera;
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
