#include "hybrid_vo/datasets/kitti_writer.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <opencv2/imgcodecs.hpp>

#include "hybrid_vo/datasets/kitti.h"
#include "hybrid_vo/datasets/text_file.h"

namespace hybrid_vo {
namespace datasets {
namespace {

namespace fs = std::filesystem;

// KITTI writes %e; 13 significant digits keep the poses exact to far below a micrometre.
std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.12e", value);
  return text;
}

std::string projection_row(const char* label, const PinholeCamera& c, double tx) {
  return std::string(label) + " " + number(c.fx) + " 0 " + number(c.cx) + " " + number(tx) +
         " 0 " + number(c.fy) + " " + number(c.cy) + " 0 0 0 1 0\n";
}

bool write_png(const std::string& path, const cv::Mat& image, std::string* error) {
  bool written = false;
  try {
    written = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    return fail(error, path + ": cannot write: " + e.what());
  }
  return written || fail(error, path + ": cannot write");
}

}  // namespace

bool KittiWriter::open(const std::string& root, const std::string& name,
                       const PinholeCamera& camera, double baseline, std::string* error) {
  if (!camera.valid()) return fail(error, "KITTI writer: invalid camera intrinsics");
  if (!std::isfinite(baseline) || baseline < 0.0)
    return fail(error, "KITTI writer: the baseline must be 0 (mono) or positive");
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos)
    return fail(error, "KITTI writer: '" + name + "' is not a sequence name");
  const fs::path sequence = fs::path(root) / "sequences" / name;
  const fs::path poses = fs::path(root) / "poses" / (name + ".txt");
  std::error_code ec;
  if (fs::exists(sequence, ec) || fs::exists(poses, ec))
    return fail(error, (fs::exists(sequence, ec) ? sequence : poses).string() +
                           ": already exists; remove it or choose another name");
  stereo_ = baseline > 0.0;
  for (const fs::path& dir : {sequence / "image_0", poses.parent_path()}) {
    fs::create_directories(dir, ec);
    if (ec) return fail(error, dir.string() + ": cannot create: " + ec.message());
  }
  if (stereo_) {
    fs::create_directories(sequence / "image_1", ec);
    if (ec) return fail(error, (sequence / "image_1").string() + ": cannot create: " + ec.message());
  }
  sequence_dir_ = sequence.string();
  poses_path_ = poses.string();
  std::ofstream calib(sequence / "calib.txt");
  calib << projection_row("P0:", camera, 0.0);
  if (stereo_) calib << projection_row("P1:", camera, -camera.fx * baseline);
  calib.close();
  if (!calib) return fail(error, (sequence / "calib.txt").string() + ": cannot write");
  times_.open(sequence / "times.txt");
  poses_.open(poses);
  if (!times_) return fail(error, (sequence / "times.txt").string() + ": cannot write");
  if (!poses_) return fail(error, poses_path_ + ": cannot write");
  frames_ = 0;
  return true;
}

bool KittiWriter::add_frame(double time, const cv::Mat& left, const cv::Mat& right,
                            const Eigen::Matrix3d& R_world_from_camera,
                            const Eigen::Vector3d& centre, std::string* error) {
  if (!times_.is_open()) return fail(error, "KITTI writer: not open");
  const std::string frame = "frame " + std::to_string(frames_);
  if (!std::isfinite(time) || (frames_ > 0 && !(time > last_time_)))
    return fail(error, sequence_dir_ + ": " + frame + ": time " + number(time) +
                           " does not increase");
  if (!R_world_from_camera.allFinite() || !centre.allFinite())
    return fail(error, poses_path_ + ": " + frame + ": the pose is not finite");
  // Every image of the sequence is 8-bit grey of one size, as the readers expect.
  auto check_image = [&](const cv::Mat& image, const char* side) {
    if (image.empty() || image.type() != CV_8UC1)
      return fail(error, sequence_dir_ + ": " + frame + ": " + side + " image is not 8-bit grey");
    if (frames_ > 0 && image.size() != size_)
      return fail(error, sequence_dir_ + ": " + frame + ": " + side + " image is " +
                             std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                             ", not " + std::to_string(size_.width) + "x" +
                             std::to_string(size_.height) + " as before");
    return true;
  };
  if (!check_image(left, "left")) return false;
  if (stereo_ && !check_image(right, "right")) return false;
  if (stereo_ && right.size() != left.size())
    return fail(error, sequence_dir_ + ": " + frame + ": the right image's size is not the left's");
  if (!write_png(kitti_image_path(sequence_dir_, 0, frames_), left, error)) return false;
  if (stereo_ && !write_png(kitti_image_path(sequence_dir_, 1, frames_), right, error))
    return false;
  times_ << number(time) << "\n";
  std::string line;
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 4; ++col)
      line += number(col < 3 ? R_world_from_camera(row, col) : centre(row)) +
              (row == 2 && col == 3 ? "\n" : " ");
  poses_ << line;
  if (!times_ || !poses_) return fail(error, sequence_dir_ + ": " + frame + ": write failed");
  last_time_ = time;
  size_ = left.size();
  ++frames_;
  return true;
}

bool KittiWriter::close(std::string* error) {
  if (!times_.is_open()) return fail(error, "KITTI writer: not open");
  times_.close();
  poses_.close();
  if (!times_ || !poses_) return fail(error, sequence_dir_ + ": write failed");
  if (frames_ == 0) return fail(error, sequence_dir_ + ": no frames");
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
