#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/lines/direction_association.h"  // VpObservation

namespace hybrid_vo {

struct VpTrackerOptions {
  // A detection joins the closest track within this angle (sign-agnostic, in the odometry frame)
  // that also passes the chi-square gate below.
  double association_angle_deg = 3.0;
  // A track that went this many frames in a row without a detection survives; one more drops it.
  int max_misses = 5;
  // Detections fused (in total) before a track is confident and feeds priors: clutter rarely
  // recurs in the same direction.
  int confirm_hits = 3;
  // No new tracks beyond this many; <= 0 means no cap.
  int max_tracks = 16;
  // Random walk of a track's direction per frame (degrees, per axis): how fast the track may
  // follow the odometry frame's rotational drift. Small: the track anchors the rotation.
  double process_noise_deg = 0.02;
  // Chi-square gate (2 dof) of a detection against its track, under the track's covariance plus
  // the detection's: 9.21 keeps 99 % of consistent detections.
  double gate_chi2 = 9.21;
  // A track whose associated detections fail the gate this many frames in a row is dropped: its
  // direction no longer agrees with the rotation the points support.
  int max_gate_failures = 2;
  // Sigma given to a detection without a usable covariance, and the floor of every detection's
  // sigma (degrees): no detection is trusted beyond what rounding and lens models allow.
  double default_sigma_deg = 1.0;
  double min_sigma_deg = 0.005;
};

struct VpTrack {
  int id = -1;  // stable, never reused (not even after reset)
  // Unit, in the odometry frame, with the sign of the track's first detection.
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  // Of the direction (rad^2, 3x3 of rank 2, in the tangent plane of `direction`).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int hits = 0;     // detections fused so far
  int misses = 0;   // consecutive frames without a fused detection
  int age = 0;      // frames since creation (0 in the frame that created it)
  bool confident = false;  // hits >= confirm_hits
  int last_update = -1;    // the frame (count of update calls) of the last fused detection
  // The gate: the last associated detection's chi-square, whether it passed, failures in a row
  // and in total.
  double last_chi2 = 0.0;
  bool last_gate_passed = true;
  int gate_failures = 0, total_gate_failures = 0;
  // Standard deviation of the direction, degrees: sqrt of the covariance's largest eigenvalue.
  double sigma_deg() const;
};

// The camera's orientation after anchor(): the odometry's orientation corrected by the directions
// of the confident tracks seen again.
struct AnchoredOrientation {
  Eigen::Matrix3d R_world_from_camera = Eigen::Matrix3d::Identity();
  // Of the orientation's left increment in the odometry frame (rad^2).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int anchors = 0;   // observations that corrected it
  int rejected = 0;  // observations of a confident track that failed the chi-square test
  double correction_deg = 0.0;
};

// Per observation of an update: its track (or -1), and the gate's verdict.
struct VpAssociation {
  int track_id = -1;
  double chi2 = 0.0;       // against the track; 0 when it started a track or was ignored
  bool gated_out = false;  // associated by angle but failed the chi-square gate
};

// Carries VP directions across frames in the odometry frame (DESIGN.md, "Vanishing points") as a
// Kalman filter on the sphere: a VP is a scene direction, so once rotated into the odometry frame
// it stays put up to the odometry's rotational drift (the process noise). Each track has a
// covariance, fused from its detections' covariances; detections that disagree with it beyond
// the gate are not fused, and a track that keeps failing is dropped. The estimator receives the
// tracks as priors (`priors`), weighted by their covariance, never as fixed directions.
//
// Intended use per frame k+1 of the odometry, with R_wc[k] the rotation of camera k into odometry:
//   pair.vp_priors = tracker.priors(R_wc[k], pair.vps);   // the estimator gates and uses them
//   ... estimate R (X2 = R X1 + t), R_wc[k+1] = R_wc[k] * R^T ...
//   tracker.update(R_wc[k+1], the pair's inlier VPs seen in image 2, with covariances);
// and once, for the first pair, tracker.update(R_wc[0], its VPs in image 1) beforehand.
class VpTracker {
 public:
  explicit VpTracker(const VpTrackerOptions& options = {});

  // One frame: predicts every track (process noise), then associates each valid observation with
  // the closest track within the association angle, one observation per track, closest first.
  // An associated observation inside the chi-square gate is fused; outside, the track counts a
  // gate failure and is dropped after max_gate_failures in a row. Unassociated observations start
  // tracks, most certain first, unless they duplicate a track or max_tracks tracks exist.
  // Ignored (track_id -1): non-finite or zero directions, non-finite covariances. An invalid
  // rotation (non-finite, not orthonormal within 1e-6, or a reflection) leaves the tracker
  // untouched and ignores every observation.
  std::vector<VpAssociation> update(const Eigen::Matrix3d& R_world_from_camera,
                                    const std::vector<VpObservation>& observations);

  // Current tracks in order of creation (increasing id).
  const std::vector<VpTrack>& tracks() const { return tracks_; }
  // The track with this id, or nullptr once it is dropped.
  const VpTrack* find(int id) const;

  // Priors for the next pair's VP matches: for each match whose d1 (camera 1, rotated into
  // odometry by R_world_from_camera1) lies within the association angle of a confident track, the
  // track's direction and covariance in camera 1 (plus one step of process noise), signed like
  // d1. One match per track, closest first; the others get an invalid prior. An invalid rotation
  // gives only invalid priors.
  std::vector<VpPrior> priors(const Eigen::Matrix3d& R_world_from_camera1,
                              const std::vector<VpMatch>& matches) const;

  // Orientation anchoring (issue 30): a VP is a fixed scene direction, so the confident tracks are
  // an absolute reference for the camera's rotation, which the frame-to-frame odometry can only
  // accumulate. Given the odometry's orientation of the current camera and its uncertainty (the
  // covariance of a left increment in the odometry frame, grown by every pair since it was last
  // anchored), each observation associated with a confident track corrects it by a Kalman update
  // on the rotation, under the track's and the observation's covariances. An observation whose
  // innovation fails the chi-square gate is left out: where the odometry is still certain, a VP
  // that disagrees is the one that is wrong; where it has drifted, its grown covariance lets the
  // tracks pull it back. Observations are taken most certain first. The tracks are unchanged
  // (update them with the anchored orientation afterwards). An invalid rotation or covariance
  // returns the input unchanged.
  AnchoredOrientation anchor(const Eigen::Matrix3d& R_world_from_camera,
                             const Eigen::Matrix3d& covariance,
                             const std::vector<VpObservation>& observations) const;

  // Drops every track, e.g. when time goes backwards; ids keep increasing.
  void reset() { tracks_.clear(); }

  const VpTrackerOptions& options() const { return options_; }
  int frames() const { return frame_; }

 private:
  // Per direction (odometry frame; `valid` marks the usable ones) its track's index or -1: the
  // nearest within association_angle_deg, one to one, among every track or only the confident.
  std::vector<int> associate_with_tracks(const std::vector<Eigen::Vector3d>& directions,
                                         const std::vector<char>& valid,
                                         bool confident_only) const;

  VpTrackerOptions options_;
  std::vector<VpTrack> tracks_;
  int next_id_ = 0;
  int frame_ = 0;  // update calls so far
};

}  // namespace hybrid_vo
