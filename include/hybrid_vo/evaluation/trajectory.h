#pragma once

// Trajectory comparison shared by the evaluation tools: camera poses by time, relative errors,
// alignment (Umeyama) and drift.

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace hybrid_vo {
namespace evaluation {

// Camera-to-world poses by timestamp (seconds).
struct StampedPose {
  double stamp = 0.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world from camera
  Eigen::Vector3d c = Eigen::Vector3d::Zero();      // camera centre in the world
};
using Trajectory = std::vector<StampedPose>;

// The pose of `trajectory` at `stamp`, within `tolerance` seconds of a sample (nearest sample).
bool pose_at(const Trajectory& trajectory, double stamp, double tolerance, StampedPose* pose);

// Least-squares similarity (with_scale) or rigid transform taking `from` onto `to` (Umeyama
// 1991): to ~ s R from + t. False with fewer than 3 points or degenerate ones.
bool umeyama(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to,
             bool with_scale, Eigen::Matrix3d* R, Eigen::Vector3d* t, double* s);

// An estimated pose and the ground truth at its stamp.
struct PosePair {
  StampedPose estimate, truth;
};

// The estimate's poses that have a ground-truth pose within `tolerance` seconds (the nearest
// sample), sorted by stamp. Poses with a non-finite stamp, rotation or centre, in the estimate
// or in the truth, are left out: they are not poses.
std::vector<PosePair> match_poses(const Trajectory& estimate, const Trajectory& truth,
                                  double tolerance);

// Rotation error over windows of `window_s` seconds: for each pose i, the pose j whose stamp is
// nearest to stamp_i + window_s, skipped unless it is within 10 % of the window; the error of
// the relative rotation i -> j is the angle of R_est_rel^T R_gt_rel, in degrees. Drift accumulates over the window, so a constant rotation
// bias of b degrees per frame gives b times the frames per window. Empty when the poses span
// less than a window or window_s is not a positive number.
std::vector<double> window_rotation_errors_deg(const std::vector<PosePair>& poses,
                                               double window_s);

// The orientation error of each pose relative to the first, in degrees: the angle of
// (R_est_0^T R_est_k)^T (R_gt_0^T R_gt_k). Zero for the first pose; it accumulates every
// rotation error since (a bias of b degrees per frame about one axis gives b k).
std::vector<double> orientation_errors_deg(const std::vector<PosePair>& poses);

constexpr double kDefaultRotationWindowSeconds = 1.0;

struct TrajectoryErrors {
  int pairs = 0;                    // consecutive pose pairs compared
  std::vector<double> rot_err_deg;  // per pair: rotation error of the relative motion
  std::vector<double> dir_err_deg;  // per pair: angle between the translation directions
  // Rotation measures in degrees; NaN when there is nothing to measure (fewer than 2 poses, or
  // for the windows a sequence shorter than one window).
  double rot_pair_median_deg = NAN;  // median of rot_err_deg
  double dir_median_deg = NAN;       // median of dir_err_deg
  double window_s = kDefaultRotationWindowSeconds;
  std::vector<double> rot_window_err_deg;  // window_rotation_errors_deg over window_s
  double rot_window_median_deg = NAN;
  // orientation_errors_deg: at the last compared pose, and the largest over all of them.
  double orientation_last_deg = NAN, orientation_max_deg = NAN;
  double rpe_trans = 0.0;           // RMSE of the relative translation (after scale alignment)
  double rpe_rot_deg = 0.0;         // RMSE of the relative rotation
  double ate = 0.0;                 // RMSE of positions after alignment
  double scale = 1.0;               // applied to the estimate
  // KITTI-style drift over sub-sequences of 100..800 m (or fractions of the path when shorter):
  // mean translation error in percent of the distance and rotation in degrees per 100 m. Zero
  // segments when the path is too short.
  int drift_segments = 0;
  double drift_trans_percent = 0.0;
  double drift_rot_deg_per_100m = 0.0;
};

// Compares an estimated trajectory with the ground truth at the estimate's stamps (match_poses
// within `tolerance`). With `with_scale` (monocular), a similarity aligns them for ATE and RPE;
// otherwise a rigid transform. Pairs are consecutive compared poses; the rotation windows are
// `window_s` long.
TrajectoryErrors compare_trajectories(const Trajectory& estimate, const Trajectory& truth,
                                      bool with_scale, double tolerance,
                                      std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>*
                                          aligned = nullptr,
                                      double window_s = kDefaultRotationWindowSeconds);

// The rotation of camera `to` relative to camera `from` of a camera-to-world trajectory, as a
// relative pose has it: X_to = R X_from.
Eigen::Matrix3d relative_rotation(const StampedPose& from, const StampedPose& to);

// The rotation vector (degrees) of a * b^T: how far rotation a is from rotation b, about which
// axis (in the frame both map into).
Eigen::Vector3d rotation_difference_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

// How a reference's relative rotations differ from measured ones of the same motions, to first
// order: e = log(R_reference R_measured^T) ~ scale * theta + tilt x theta, theta the reference's
// rotation vector. `scale` is a rotation-rate error; `tilt` a constant rotation between the two
// frames, which turns every rotation axis. Least squares over the pairs whose difference is
// within 3 times the median, refitted on those whose residual is (failed measurements are
// outliers, not an offset). ok is false with fewer than 3 pairs, sizes that differ, non-finite
// input, or rotations too small (or about one axis only) to tell the four numbers apart.
struct RotationOffsetFit {
  bool ok = false;
  int pairs = 0;  // kept in the refit
  double scale = 0.0;                                  // 0.01: the reference turns 1 % more
  Eigen::Vector3d tilt_deg = Eigen::Vector3d::Zero();  // rotation vector, degrees
  double rms_before_deg = 0.0, rms_after_deg = 0.0;    // per component, before and after the fit
};
RotationOffsetFit fit_rotation_offset(const std::vector<Eigen::Matrix3d>& reference,
                                      const std::vector<Eigen::Matrix3d>& measured);

// TUM format: "timestamp tx ty tz qx qy qz qw" per line, '#' comments. False with file:line.
bool read_tum_trajectory(const std::string& path, Trajectory* trajectory, std::string* error);
// Writes the same format (stamps to the microsecond, positions and quaternions to 1e-9), which
// read_tum_trajectory, evo and the TUM tools read. False with the reason when the file cannot be
// written or a pose is not finite.
bool write_tum_trajectory(const std::string& path, const Trajectory& trajectory,
                          std::string* error);

}  // namespace evaluation
}  // namespace hybrid_vo
