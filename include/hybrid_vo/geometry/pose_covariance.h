#pragma once

#include <cmath>

#include <Eigen/Core>

namespace hybrid_vo {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// First-order covariances of an odometry's pose and velocity, in ROS's order (nav_msgs/Odometry):
// a pose's is [position x y z, rotation x y z], the rotation a left increment of the orientation
// (about the parent frame's fixed axes), rad; a twist's [linear, angular] in the child frame. A
// pair's motion X_cur = R X_ref + t has the covariance [rotation as a left increment of R (the
// current camera's frame), t].

// The current camera's pose covariance after one integrated pair: centre = keyframe centre -
// R_wc t, with R_wc (camera into odometry) = the keyframe's R_wc R^T.
//   keyframe               the keyframe pose's covariance (with its position-rotation terms)
//   R_wc, t                the current orientation and the pair's translation, as integrated
//   motion_covariance      the pair's
//   orientation_covariance what the orientation filter holds for R_wc: the chain's prediction,
//                          less where the map corrected it, more where it added drift
// The orientation block of the result is orientation_covariance; the position and cross terms
// follow the chain to first order (see the .cc for how the filter's step enters). False, leaving
// *out, when an input or the result is not finite.
bool propagate_pose_covariance(const Matrix6d& keyframe, const Eigen::Matrix3d& R_wc,
                               const Eigen::Vector3d& t, const Matrix6d& motion_covariance,
                               const Eigen::Matrix3d& orientation_covariance, Matrix6d* out);

// A monocular odometry's unit drifts (issue 58): it is the first pair's length, and each keyframe
// hands it on through the depths it triangulates with its own pair's length, so that an error of
// that length stays in every later one (Strasdat, Montiel and Davison, "Scale drift-aware large
// scale monocular SLAM", RSS 2010). Its log is a seventh state after the pose's six, [position,
// rotation, log-scale of the unit]: every pair's translation scales with its keyframe's unit (the
// position moves by -R_wc t per unit of it), and a pair that hands the unit on (`hands_on`: a
// keyframe made by a pair whose length was fitted) adds its own relative length error, the part of
// its translation's error along t over |t|, to it. Without hands_on and with a log-scale known
// exactly (stereo: every pair's length is metric) this is propagate_pose_covariance.
using Matrix7d = Eigen::Matrix<double, 7, 7>;
bool propagate_scaled_pose_covariance(const Matrix7d& keyframe, const Eigen::Matrix3d& R_wc,
                                      const Eigen::Vector3d& t, const Matrix6d& motion_covariance,
                                      const Eigen::Matrix3d& orientation_covariance,
                                      bool hands_on, Matrix7d* out);

// The pose covariance as an odometry integrates its pairs (what VisualOdometry keeps), with the
// log-scale of a monocular unit (above): zero at the origin, which is exact by definition.
class PoseCovarianceChain {
 public:
  Matrix6d covariance() const { return covariance_.topLeftCorner<6, 6>(); }
  const Matrix7d& scaled_covariance() const { return covariance_; }
  // Integrated pairs whose covariance was missing (the position then grew by the orientation's
  // uncertainty alone) or whose inputs were not finite (the last covariance kept).
  int gaps() const { return gaps_; }
  // One pair integrated onto the keyframe's covariance (propagate_scaled_pose_covariance);
  // motion_covariance null when the pair has none. A keyframe's 6x6 covariance has an exact unit.
  void integrate(const Matrix7d& keyframe, const Eigen::Matrix3d& R_wc, const Eigen::Vector3d& t,
                 const Matrix6d* motion_covariance,
                 const Eigen::Matrix3d& orientation_covariance, bool hands_on = false);
  void integrate(const Matrix6d& keyframe, const Eigen::Matrix3d& R_wc, const Eigen::Vector3d& t,
                 const Matrix6d* motion_covariance,
                 const Eigen::Matrix3d& orientation_covariance);
  // The unit's log-scale grows by this variance (what a mono keyframe hands on besides its
  // length's error); a negative or non-finite one is ignored.
  void add_unit_variance(double variance) {
    if (variance > 0.0 && std::isfinite(variance)) covariance_(6, 6) += variance;
  }
  void reset() { covariance_.setZero(); }  // the gaps stay counted

 private:
  Matrix7d covariance_ = Matrix7d::Zero();
  int gaps_ = 0;
};

// The covariance of T_bc T_wc T_bc^-1, the body in odom (odom being the body at the first
// camera), from that of the camera pose T_wc = (R_wc, centre) in the first camera's frame;
// T_bc = (R_bc, t_bc) is the static body-from-camera transform.
Matrix6d body_pose_covariance(const Matrix6d& camera, const Eigen::Matrix3d& R_wc,
                              const Eigen::Matrix3d& R_bc, const Eigen::Vector3d& t_bc);

// The body's mean velocity over a pair of `dt` seconds, in the body frame of the current frame,
// from the pair's motion through the static transform (identity: the camera's own), with its
// covariance. False when dt is not positive or an input is not finite.
struct PairTwist {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero(), angular = Eigen::Vector3d::Zero();
  Matrix6d covariance = Matrix6d::Zero();  // [linear, angular]
};
bool pair_twist(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                const Matrix6d& motion_covariance, double dt, const Eigen::Matrix3d& R_bc,
                const Eigen::Vector3d& t_bc, PairTwist* out);

// Finite, symmetric (to round-off) and positive semi-definite (to round-off of its scale).
bool is_covariance(const Matrix6d& C);

}  // namespace hybrid_vo
