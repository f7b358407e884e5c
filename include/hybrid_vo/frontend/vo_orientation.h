#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/estimation/relative_pose_estimator.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/lines/vp_tracker.h"

namespace hybrid_vo {

struct VisualOdometryOptions;

// The visual odometry's orientation (camera into odometry) and what holds it: each estimated
// pair's rotation carries the keyframe's orientation on, its uncertainty growing by the pair's
// rotation covariance, and the confident VP tracks it sees anchor it (VpTracker::anchor); the
// tracker gives the pair's VPs their priors and follows them from frame to frame. Also the
// camera's last rotation rate, which predicts how the segments move in the next frame. Used by
// VisualOdometry (use_vp_tracker, anchor_orientation, rotation_drift_floor_deg, vp_tracker).
class VoOrientation {
 public:
  explicit VoOrientation(const VisualOdometryOptions& options);
  // Drops the VP tracks and the rotation rate, and keeps the orientation (a new keyframe chain).
  void restart();
  // restart(), and the orientation back to identity, without uncertainty.
  void reset();

  const Eigen::Matrix3d& R_wc() const { return R_wc_; }
  // Of a left increment of R_wc in the odometry frame (rad^2).
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  const VpTracker& vp_tracker() const { return tracker_; }

  // How the camera turning on at its last rate for `dt` seconds moves the image: K R K^-1
  // (identity without a rate).
  Eigen::Matrix3d segment_motion(const PinholeCamera& camera, double dt) const;

  // Before a pair is estimated: its VP matches' priors from the tracks (m->vp_priors), with the
  // keyframe's orientation `keyframe_R_wc` and intrinsics `keyframe_K`. The first pair's VPs,
  // as seen in the keyframe, start the tracks. Returns the track of each prior, or -1.
  std::vector<int> add_vp_priors(const Eigen::Matrix3d& keyframe_R_wc,
                                 const Eigen::Matrix3d& keyframe_K, TwoViewMatches* m);

  // A pair's outcome for the orientation: the current camera's, anchored, and what anchored it.
  struct Oriented {
    RelativePose pose;        // the estimator's, with the anchored rotation
    Eigen::Matrix3d R_wc = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    std::vector<VpObservation> seen;  // the VPs the pose accepts, as seen in the current image
    AnchoredOrientation anchoring;    // with anchor_orientation
  };
  // The current camera's orientation from the keyframe's (`keyframe_R_wc`, its covariance) and
  // the pair's estimate `est` of matches `m`, anchored by the tracks; `K` is the current
  // camera's. Changes nothing: advance() takes the outcome on.
  Oriented orient(const Eigen::Matrix3d& keyframe_R_wc, const Eigen::Matrix3d& keyframe_covariance,
                  const RelativePoseEstimate& est, const TwoViewMatches& m,
                  const Eigen::Matrix3d& K) const;
  // The pair accepted: its orientation becomes the odometry's, its rotation `pair_R` over `dt`
  // seconds (when positive) the rotation rate, and the tracker follows the VPs seen. Returns the
  // tracker's association of each (none without the tracker).
  std::vector<VpAssociation> advance(const Oriented& oriented, const Eigen::Matrix3d& pair_R,
                                     double dt);

 private:
  const bool use_tracker_, anchor_;
  const double drift_floor_deg_;
  // The first pair's VPs, as the tracks' seeds: the covariance of their fit at a third of the
  // VP detection's inlier threshold, plus a third of the estimator's VP threshold.
  const double seed_sigma_px_, seed_sigma_deg_;
  VpTracker tracker_;
  bool seeded_ = false;
  Eigen::Matrix3d R_wc_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d covariance_ = Eigen::Matrix3d::Zero();
  // Rad/s, the rotation vector of X2 = R X1 per second.
  Eigen::Vector3d angular_velocity_ = Eigen::Vector3d::Zero();
};

}  // namespace hybrid_vo
