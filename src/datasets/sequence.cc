#include "hybrid_vo/datasets/sequence.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "hybrid_vo/datasets/text_file.h"

namespace hybrid_vo {
namespace datasets {

RelativePose relative_pose(const Frame& frame_i, const Frame& frame_j) {
  const Eigen::Matrix3d Rj_t = frame_j.R_wc.transpose();
  return {Rj_t * frame_i.R_wc, Rj_t * (frame_i.c_w - frame_j.c_w)};
}

RelativePose relative_pose(const Sequence& sequence, int i, int j) {
  if (i < 0 || j < 0 || i >= sequence.size() || j >= sequence.size())
    throw std::out_of_range("relative_pose: frames (" + std::to_string(i) + ", " +
                            std::to_string(j) + ") outside sequence '" + sequence.name +
                            "' of " + std::to_string(sequence.size()) + " frames");
  return relative_pose(sequence.frames[i], sequence.frames[j]);
}

std::vector<PairWithGt> make_pairs(const Sequence& sequence, int step) {
  std::vector<PairWithGt> pairs;
  if (step < 1) return pairs;
  for (int i = 0; i + step < sequence.size(); ++i) {
    const Frame& a = sequence.frames[i];
    const Frame& b = sequence.frames[i + step];
    PairWithGt pair;
    pair.image_path0 = a.image_path;
    pair.image_path1 = b.image_path;
    pair.camera0 = a.camera;
    pair.camera1 = b.camera;
    pair.pose = relative_pose(a, b);
    pair.index0 = i;
    pair.index1 = i + step;
    pairs.push_back(pair);
  }
  return pairs;
}

CameraModel scaled(const CameraModel& camera, double s) { return scaled(camera, s, s); }

CameraModel scaled(const CameraModel& camera, double sx, double sy) {
  CameraModel out = camera;
  PinholeCamera& p = out.pinhole;
  p.fx *= sx;
  p.fy *= sy;
  p.cx = (p.cx + 0.5) * sx - 0.5;
  p.cy = (p.cy + 0.5) * sy - 0.5;
  if (p.width > 0) p.width = static_cast<int>(std::lround(p.width * sx));
  if (p.height > 0) p.height = static_cast<int>(std::lround(p.height * sy));
  return out;
}

CameraModel resized(const CameraModel& camera, int width, int height) {
  const PinholeCamera& p = camera.pinhole;
  if (p.width <= 0 || p.height <= 0 || width <= 0 || height <= 0) return camera;
  CameraModel out = scaled(camera, static_cast<double>(width) / p.width,
                           static_cast<double>(height) / p.height);
  out.pinhole.width = width;  // exact, whatever the rounding of the factors
  out.pinhole.height = height;
  return out;
}

bool pinhole_from_matrix(const Eigen::Matrix3d& K, const std::string& path, int line,
                         PinholeCamera* camera, std::string* error) {
  // Intrinsics are given to a few digits; a relative 1e-9 is "zero" for any written skew.
  const double scale = std::max(std::abs(K(0, 0)), std::abs(K(1, 1)));
  if (std::abs(K(0, 1)) > 1e-9 * scale)
    return fail(error, located(path, line, "K has skew K(0,1) = " + std::to_string(K(0, 1)) +
                                               ", which PinholeCamera cannot represent"));
  if (K(1, 0) != 0.0 || K(2, 0) != 0.0 || K(2, 1) != 0.0 || K(2, 2) != 1.0) {
    std::ostringstream message;
    message << "K is not upper triangular with K(2,2) = 1: rows [" << K.row(0) << "; "
            << K.row(1) << "; " << K.row(2) << "]";
    return fail(error, located(path, line, message.str()));
  }
  if (!(K(0, 0) > 0.0) || !(K(1, 1) > 0.0))
    return fail(error, located(path, line, "K has non-positive focal lengths"));
  camera->fx = K(0, 0);
  camera->fy = K(1, 1);
  camera->cx = K(0, 2);
  camera->cy = K(1, 2);
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
