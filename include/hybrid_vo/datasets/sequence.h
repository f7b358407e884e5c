#pragma once

// Image sequences with intrinsics and ground-truth camera poses, and the image pairs with
// ground-truth relative poses that the evaluation tools build from them. The readers are in
// datasets/readers.h.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/features/camera_model.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo {
namespace datasets {

// One image and its ground truth. The pose is camera-to-world, as KITTI, TUM and Strecha all
// give it: X_world = R_wc * X_cam + c_w, so c_w is the camera centre in world coordinates.
struct Frame {
  std::string image_path;  // the data set path joined with the image's relative path
  double timestamp = 0.0;  // seconds (KITTI times.txt, TUM rgb.txt); the frame index for Strecha
  Eigen::Matrix3d R_wc = Eigen::Matrix3d::Identity();
  Eigen::Vector3d c_w = Eigen::Vector3d::Zero();
  // This image's intrinsics. The same for every frame of KITTI and TUM; Strecha has one per image.
  // KITTI and Strecha images are undistorted (zero coefficients); TUM fr1 images are distorted.
  CameraModel camera;
};

struct Sequence {
  std::string name;    // the folder name: "seq0x", "tum_fr1_plant_19", "fountain-P11"
  std::string format;  // "kitti", "tum" or "strecha"
  std::vector<Frame> frames;
  int skipped_frames = 0;  // images listed but left out for lack of ground truth (TUM)

  int size() const { return static_cast<int>(frames.size()); }
};

// The relative pose from frame i to frame j in our convention X_j = R X_i + t, i.e.
// inv(T_j) * T_i for camera-to-world T: R = R_wc_jᵀ R_wc_i, t = R_wc_jᵀ (c_i - c_j). The
// translation is metric (the data set's unit); callers normalise it for two-view evaluation.
RelativePose relative_pose(const Frame& frame_i, const Frame& frame_j);
// Same by index; throws std::out_of_range for an index outside the sequence.
RelativePose relative_pose(const Sequence& sequence, int i, int j);

// Two images with their intrinsics and the ground-truth relative pose X1 = R X0 + t.
struct PairWithGt {
  std::string image_path0, image_path1;
  CameraModel camera0, camera1;
  RelativePose pose;  // metric, or in the data set's unit (SfM scale for some SuperGlue lists)
  // SuperGlue's in-plane rotation hints: match_pairs.py turns each image by np.rot90(image, k)
  // before matching. camera0/1 and pose always refer to the images as stored (unrotated); 0 for
  // pairs made from a Sequence.
  int rotation0 = 0, rotation1 = 0;
  // Frame indices in the sequence the pair came from; -1 for pairs read from a pairs file.
  int index0 = -1, index1 = -1;
};

// The pairs (i, i + step) for i = 0, 1, ... while i + step < size; empty for step < 1.
std::vector<PairWithGt> make_pairs(const Sequence& sequence, int step);

// Intrinsics of the image resized by factors (sx, sy), e.g. for evaluation at a smaller scale
// (--resize S). Pixel centres sit at integer coordinates (OpenCV, KITTI, TUM, Strecha), so the
// resize maps x to (x + 0.5) s - 0.5: f' = f s and c' = (c + 0.5) s - 0.5. This is exactly the
// mapping of cv::resize. Distortion coefficients act on normalised coordinates and are kept. A
// known size becomes round(width * sx) x round(height * sy), the size cv::resize(src, dst,
// cv::Size(), s, s) produces. (SuperGlue's scale_intrinsics uses c' = c s, off by up to 0.5 px.)
CameraModel scaled(const CameraModel& camera, double s);
CameraModel scaled(const CameraModel& camera, double sx, double sy);
// Intrinsics of the image resized to exactly width x height, as cv::resize(src, dst,
// cv::Size(width, height)) does: the factors are width / camera width and height / camera
// height. The camera's size must be known (non-zero); otherwise the camera is returned unchanged.
CameraModel resized(const CameraModel& camera, int width, int height);

// The pinhole camera of an intrinsic matrix K = [fx 0 cx; 0 fy cy; 0 0 1], as the data sets write
// it. False, with the error located at path:line, for skew, a bottom row other than (0 0 1), or
// non-positive focal lengths.
bool pinhole_from_matrix(const Eigen::Matrix3d& K, const std::string& path, int line,
                         PinholeCamera* camera, std::string* error);

}  // namespace datasets
}  // namespace hybrid_vo
