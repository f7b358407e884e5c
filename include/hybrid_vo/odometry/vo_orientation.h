#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/estimation/relative_pose_estimator.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/direction_map/orientation_filter.h"

namespace hybrid_vo {

struct VisualOdometryOptions;

// The visual odometry's orientation (camera into odometry) and what holds it: each estimated
// pair's rotation carries the keyframe's orientation on, its uncertainty growing by the pair's
// rotation covariance (much more across a blank wall), and the map of world directions corrects
// it wherever the camera sees them, finds them again after a blank wall, and overrules a pair
// whose rotation its directions contradict (OrientationFilter). The map gives the pair's VPs their
// priors. Also the camera's last rotation rate, which predicts how the segments move in the next
// frame and carries a blank wall when coasting. Used by VisualOdometry (use_direction_map: the map,
// anchor_orientation: its corrections, orientation).
class VoOrientation {
 public:
  explicit VoOrientation(const VisualOdometryOptions& options);
  // Drops the map and the rotation rate, and keeps the orientation (a new keyframe chain).
  void restart();
  // restart(), and the orientation back to identity, without uncertainty.
  void reset();

  const Eigen::Matrix3d& R_wc() const { return R_wc_; }
  // Of a left increment of R_wc in the odometry frame (rad^2): the filter's.
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  // What the orientation's uncertainty is, reported: the filter's, which takes the pairs' errors
  // as independent (so that the map is not overruled by what a chain of pairs cannot know), with
  // their sum bounded as if they were not. The pairs' errors correlate over time (rolling
  // shutter, calibration, a ground truth's own; TUM's pairs share a bias of 0.14 degrees); for
  // errors of sigma s_k whose correlation is unknown, the sum's sigma is at most sum s_k, not
  // sqrt(sum s_k^2). A correction by the map takes the same share of that excess as of the
  // filter's own uncertainty: strong directions remove it, weak ones leave it.
  Eigen::Matrix3d reported_covariance() const;
  const DirectionMap& direction_map() const { return filter_.map(); }

  // How the camera turning on at its last rate for `dt` seconds moves the image: K R K^-1
  // (identity without a rate).
  Eigen::Matrix3d segment_motion(const PinholeCamera& camera, double dt) const;

  // Before a pair is estimated: its VP matches' priors from the map (m->vp_priors), with the
  // keyframe's orientation `keyframe_R_wc`, its covariance and intrinsics `keyframe_K`. The first
  // pair's VPs, as seen in the keyframe, start the map. Returns the direction of each prior, or -1.
  std::vector<int> add_vp_priors(const Eigen::Matrix3d& keyframe_R_wc,
                                 const Eigen::Matrix3d& keyframe_covariance,
                                 const Eigen::Matrix3d& keyframe_K, TwoViewMatches* m);

  // A pair's outcome for the orientation: the current camera's, and the motion under it.
  struct Oriented {
    RelativePose pose;        // the pair's motion with the held rotation (and refitted t)
    RelativePose scale_pose;  // the pose whose rotation and t explain its points: the scale's
    Eigen::Matrix3d R_wc = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    OrientationEstimate estimate;  // how the map placed the camera
    // What the motion's rotation covariance lacks beyond the estimator's (rad^2, camera):
    // a blank wall's, and the calibration's share of the angle turned.
    Eigen::Matrix3d motion_rotation_extra = Eigen::Matrix3d::Zero();
  };
  // The pair the orient stage needs to know of.
  struct Pair {
    const RelativePoseEstimate* estimate = nullptr;
    const TwoViewMatches* matches = nullptr;  // undistorted pixels
    PinholeCamera keyframe_camera, camera;
    double dt = 0.0;            // seconds from the keyframe
    bool vps_detected = false;  // the estimator looked for VPs (the map needs them)
    // Its rotation rests on no epipolar translation (a rotation alone, or the stereo points'),
    // so no share of the angle turned is traded with one.
    bool independent_rotation = false;
  };
  // The current camera's orientation from the keyframe's (`keyframe_R_wc`, its covariance) and
  // the pair. Changes nothing: advance() takes the outcome on.
  Oriented orient(const Eigen::Matrix3d& keyframe_R_wc, const Eigen::Matrix3d& keyframe_covariance,
                  const Pair& pair) const;
  // The pair accepted: its orientation becomes the odometry's, its rotation over `dt` seconds
  // (when positive; not a coasted one) the rotation rate, and the map takes the frame in.
  // `motion_rotation_covariance` is the motion's rotation covariance as published.
  void advance(const Oriented& oriented, double dt,
               const Eigen::Matrix3d& motion_rotation_covariance);
  // The rotation rate from a frame answered without advance(): its rotation R (X2 = R X1) since
  // the last answered frame, `dt` seconds before.
  void set_rate(const Eigen::Matrix3d& R, double dt);
  // What reported_covariance() would be after advance(oriented, ..., motion_rotation_covariance),
  // without taking the pair on: a frame answered against a keyframe that stays.
  Eigen::Matrix3d reported_covariance(const Oriented& oriented,
                                      const Eigen::Matrix3d& motion_rotation_covariance) const;

 private:
  const bool use_map_;
  const double rotation_calibration_sigma_, full_pair_turn_fraction_;
  // The pairs' rotation sigmas (per axis) summed, and their squares, as corrections left them.
  double sigma_sum_ = 0.0, variance_sum_ = 0.0;
  // Those sums with a pair taken on (advance()).
  void accumulate(const Oriented& oriented, const Eigen::Matrix3d& motion_rotation_covariance,
                  double* sigma_sum, double* variance_sum) const;
  // The first pair's VPs, as the map's seeds: the covariance of their fit at a third of the VP
  // detection's inlier threshold, plus a third of the estimator's VP threshold.
  const double seed_sigma_px_, seed_sigma_deg_;
  OrientationFilter filter_;
  bool seeded_ = false;
  Eigen::Matrix3d R_wc_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d covariance_ = Eigen::Matrix3d::Zero();
  // Rad/s, the rotation vector of X2 = R X1 per second.
  Eigen::Vector3d angular_velocity_ = Eigen::Vector3d::Zero();
};

}  // namespace hybrid_vo
