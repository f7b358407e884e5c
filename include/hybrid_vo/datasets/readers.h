#pragma once

// Readers of the data sets with ground-truth poses (../shared/data/README.md). Each returns false
// with an error naming the file, and the line where there is one ("file:line: message"), for a
// missing file or a malformed line: wrong number of fields, non-numbers, NaN or inf, a matrix that
// is not a rotation, a missing image. On failure *sequence / *pairs are left in an unspecified
// state. Image files must exist but are not decoded (except KITTI's first, for the image size).

#include <string>
#include <vector>

#include "hybrid_vo/datasets/sequence.h"

namespace hybrid_vo {
namespace datasets {

// KITTI odometry, left grayscale camera (image_0) only. `path` is either
//   - a sequence folder <root>/sequences/<name> (with image_0/, calib.txt, times.txt), whose
//     ground truth is <root>/poses/<name>.txt, or
//   - the odometry root <root> when <root>/sequences holds exactly one sequence.
// K comes from P0 in calib.txt (rectified images: no distortion); the image size from the first
// image. times.txt and poses/<name>.txt have one line per frame (poses: 12 numbers, row-major
// 3x4 [R | c], the camera-to-world pose of cam0, metres); images are image_0/%06d.png.
bool read_kitti(const std::string& path, Sequence* sequence, std::string* error);

struct TumOptions {
  // A frame gets ground truth only when a sample lies within this time (s) of its timestamp
  // (TUM's associate.py default).
  double max_time_difference = 0.02;
  // When samples bracket the frame's time, at most max_interpolation_gap (s) apart, the pose is
  // interpolated between them (position linearly, rotation by slerp); otherwise the nearest
  // sample is taken as it is.
  bool interpolate = true;
  double max_interpolation_gap = 0.2;
};

// TUM RGB-D, a sequence folder with
//   rgb.txt          "timestamp relative/image/path" per line, '#' comments;
//   groundtruth.txt  "timestamp tx ty tz qx qy qz qw" per line, '#' comments: the colour
//                    camera's centre and orientation in the world (camera-to-world), quaternion
//                    stored x, y, z, w; samples in any order;
//   camera.txt       "key value" lines, '#' comments: fx fy cx cy required; k1 k2 p1 p2 k3
//                    (OpenCV plumb-bob, default 0) and width height (default 0 = unknown)
//                    optional; unknown or repeated keys are errors.
// Frames without ground truth within the tolerance are skipped and counted in skipped_frames; no
// frame with ground truth at all is an error.
bool read_tum(const std::string& path, Sequence* sequence, std::string* error,
              const TumOptions& options = TumOptions());

// Strecha et al. 2008 (the openMVG copy: fountain-P11, Herz-Jesus-P8, ...): a scene folder with
// images/<image> and gt_dense_cameras/<image>.camera, one frame per .camera file in name order.
// A .camera file holds 26 numbers (line breaks free): K (3x3 row-major), 3 radial distortion
// coefficients (must be 0: the images are undistorted, and a non-zero model is not supported),
// R (3x3 row-major, camera-to-world), C (the camera centre in the world), width, height. The
// projection is x ~ K Rᵀ (X - C); metric. Timestamps are the frame indices.
bool read_strecha(const std::string& path, Sequence* sequence, std::string* error);
// One .camera file as a frame without its image: camera (with the size), R_wc and c_w.
bool read_strecha_camera(const std::string& path, Frame* frame, std::string* error);
// The .camera file of an image in that layout, <scene>/gt_dense_cameras/<image>.camera for
// <scene>/images/<image>, or else <image>.camera beside the image; empty when neither exists.
std::string strecha_camera_of_image(const std::string& image_path);

// A SuperGlue pairs file with ground truth (magicleap/SuperGluePretrainedNetwork,
// assets/*_pairs_with_gt.txt, as match_pairs.py --eval reads it): 38 whitespace-separated fields
// per line,
//   name0 name1 rot0 rot1 K0 (9, row-major) K1 (9, row-major) T_0to1 (16, row-major 4x4)
// where names are relative to image_dir, rot0/rot1 are np.rot90 counts in 0..3 (see PairWithGt),
// K0/K1 are the intrinsics of the images as stored (no distortion), and T_0to1 = [R t; 0 0 0 1]
// maps camera-0 to camera-1 coordinates, X1 = R X0 + t (SuperGlue's E = [t]x R), which is our
// convention as it is. Blank lines and '#' comments are skipped; lines without ground truth (2 or
// 4 fields) are errors. Image sizes are unknown (0). With an empty image_dir the paths are the
// names as written and are not checked; otherwise every image must exist.
bool read_superglue(const std::string& pairs_file, const std::string& image_dir,
                    std::vector<PairWithGt>* pairs, std::string* error);

// Dispatch on format: "kitti", "tum" or "strecha" (default TumOptions).
bool read_sequence(const std::string& format, const std::string& path, Sequence* sequence,
                   std::string* error);

}  // namespace datasets
}  // namespace hybrid_vo
