#pragma once

// Trajectory comparison shared by the evaluation tools: camera poses by time, relative errors,
// alignment (Umeyama) and drift.

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

struct TrajectoryErrors {
  int pairs = 0;                    // consecutive pose pairs compared
  std::vector<double> rot_err_deg;  // per pair: rotation error of the relative motion
  std::vector<double> dir_err_deg;  // per pair: angle between the translation directions
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

// Compares an estimated trajectory with the ground truth at the estimate's stamps (GT matched
// within `tolerance`). With `with_scale` (monocular), a similarity aligns them for ATE and RPE;
// otherwise a rigid transform.
TrajectoryErrors compare_trajectories(const Trajectory& estimate, const Trajectory& truth,
                                      bool with_scale, double tolerance,
                                      std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>*
                                          aligned = nullptr);

// TUM format: "timestamp tx ty tz qx qy qz qw" per line, '#' comments. False with file:line.
bool read_tum_trajectory(const std::string& path, Trajectory* trajectory, std::string* error);

}  // namespace evaluation
}  // namespace hybrid_vo
