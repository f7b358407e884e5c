// Strecha multi-view benchmark reader (see readers.h for the layout).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/datasets/text_file.h"

namespace hybrid_vo {
namespace datasets {
namespace {

namespace fs = std::filesystem;

constexpr char kCameraSuffix[] = ".camera";

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

// 26 numbers, line breaks free, so each number keeps its own line for errors.
bool read_strecha_camera(const std::string& path, Frame* frame, std::string* error) {
  std::vector<std::string> lines;
  if (!read_lines(path, &lines, error)) return false;
  std::vector<std::pair<std::string, int>> tokens;
  for (size_t k = 0; k < lines.size(); ++k)
    for (const std::string& token : split_fields(lines[k]))
      tokens.emplace_back(token, static_cast<int>(k + 1));
  constexpr size_t kCount = 26;
  if (tokens.size() != kCount)
    return fail(error, located(path, tokens.empty() ? 0 : tokens.back().second,
                               "expected 26 numbers (K 9, distortion 3, R 9, C 3, width height), "
                               "found " + std::to_string(tokens.size())));
  double v[kCount];
  for (size_t k = 0; k < kCount; ++k)
    if (!parse_double(tokens[k].first, &v[k]))
      return fail(error, located(path, tokens[k].second,
                                 "number " + std::to_string(k + 1) + " '" + tokens[k].first +
                                     "' is not a finite number"));
  const int K_line = tokens[0].second, distortion_line = tokens[9].second;
  const int R_line = tokens[12].second, size_line = tokens[24].second;

  Eigen::Matrix3d K, R;
  K << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
  R << v[12], v[13], v[14], v[15], v[16], v[17], v[18], v[19], v[20];
  if (!pinhole_from_matrix(K, path, K_line, &frame->camera.pinhole, error)) return false;
  // The benchmark's images are undistorted; its radial model is not OpenCV's, so refuse rather
  // than misuse non-zero coefficients.
  if (v[9] != 0.0 || v[10] != 0.0 || v[11] != 0.0)
    return fail(error, located(path, distortion_line,
                               "non-zero radial distortion is not supported"));
  frame->camera.distortion = {0, 0, 0, 0, 0};
  if (!to_rotation(R, path, R_line, &frame->R_wc, error)) return false;
  frame->c_w = Eigen::Vector3d(v[21], v[22], v[23]);
  const double width = v[24], height = v[25];
  // Range first: converting a double beyond an int is undefined behaviour.
  constexpr double kMaxSide = std::numeric_limits<int>::max();
  if (!(width >= 1.0) || !(height >= 1.0) || width > kMaxSide || height > kMaxSide ||
      width != std::floor(width) || height != std::floor(height))
    return fail(error, located(path, size_line, "width and height must be positive integers"));
  frame->camera.pinhole.width = static_cast<int>(width);
  frame->camera.pinhole.height = static_cast<int>(height);
  return true;
}


std::string strecha_camera_of_image(const std::string& image_path) {
  const fs::path image(image_path);
  const std::string file = image.filename().string() + kCameraSuffix;
  std::error_code ec;
  for (const fs::path& candidate :
       {image.parent_path() / ".." / "gt_dense_cameras" / file, image.parent_path() / file})
    if (fs::is_regular_file(candidate, ec)) return candidate.lexically_normal().string();
  return "";
}

bool read_strecha(const std::string& path, Sequence* sequence, std::string* error) {
  fs::path dir = fs::path(path).lexically_normal();
  if (dir.has_parent_path() && dir.filename().empty()) dir = dir.parent_path();  // trailing '/'
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(error, located(path, 0, "no such directory"));
  const fs::path camera_dir = dir / "gt_dense_cameras";
  const fs::path image_dir = dir / "images";
  if (!fs::is_directory(camera_dir, ec))
    return fail(error, located(camera_dir.string(), 0, "no such directory"));

  std::vector<std::string> camera_files;
  for (const auto& entry : fs::directory_iterator(camera_dir, ec)) {
    const std::string file = entry.path().filename().string();
    if (entry.is_regular_file() && ends_with(file, kCameraSuffix)) camera_files.push_back(file);
  }
  if (camera_files.empty())
    return fail(error, located(camera_dir.string(), 0, "no *.camera files"));
  std::sort(camera_files.begin(), camera_files.end());

  sequence->name = dir.filename().string();
  sequence->format = "strecha";
  sequence->skipped_frames = 0;
  sequence->frames.assign(camera_files.size(), Frame());
  for (size_t k = 0; k < camera_files.size(); ++k) {
    Frame& frame = sequence->frames[k];
    const std::string camera_path = (camera_dir / camera_files[k]).string();
    if (!read_strecha_camera(camera_path, &frame, error)) return false;
    const std::string image =
        camera_files[k].substr(0, camera_files[k].size() - (sizeof(kCameraSuffix) - 1));
    frame.image_path = (image_dir / image).string();
    if (!fs::is_regular_file(frame.image_path, ec))
      return fail(error, located(frame.image_path, 0, "no such image (for " + camera_path + ")"));
    frame.timestamp = static_cast<double>(k);
  }
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
