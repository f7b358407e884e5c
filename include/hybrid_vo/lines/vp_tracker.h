#pragma once

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"

namespace hybrid_vo {

struct VpTrackerOptions {
  // A detection joins the closest track within this angle (sign-agnostic, in the odometry frame).
  double association_angle_deg = 3.0;
  // A track that went this many frames in a row without a detection survives; one more drops it.
  int max_misses = 5;
  // Detections (in total) before a track is confident: clutter rarely recurs in the same direction.
  int confirm_hits = 3;
  // No new tracks beyond this many; <= 0 means no cap.
  int max_tracks = 16;
  // Fraction of a track's accumulated weight kept per frame. The direction is a weighted mean over
  // roughly 1 / (1 - memory) frames: long enough to average the detector's noise, short enough to
  // follow the slow drift of the odometry frame. 1 keeps every detection at full weight.
  double memory = 0.9;
};

struct VpTrack {
  int id = -1;  // stable, never reused (not even after reset)
  // Unit, in the odometry frame, with the sign of the track's first detection.
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  int hits = 0;     // detections associated so far
  int misses = 0;   // consecutive frames without a detection
  int age = 0;      // frames since creation (0 in the frame that created it)
  bool confident = false;  // hits >= confirm_hits
  double weight = 0.0;     // accumulated, decayed weight of the detections behind `direction`
  double last_angle_deg = 0.0;  // angle of the last detection to the track before it was merged
};

// Carries VP directions across frames in the odometry frame (DESIGN.md, "Vanishing points").
// A VP is a scene direction, so once rotated into the odometry frame it stays put up to the
// odometry's rotational drift; tracks average detections there, associated by angle.
//
// Intended use per frame k+1 of the node, with R_wc[k] the rotation of camera k into odometry:
//   ids = tracker.refine_matches(R_wc[k], &pair.vps);   // smoother d1 for the estimator
//   ... estimate R (X2 = R X1 + t), R_wc[k+1] = R_wc[k] * R^T ...
//   tracker.update(R_wc[k+1], d2 of the pair's VP matches, their segment counts);
// and once, for the first pair, tracker.update(R_wc[0], d1 of its VP matches) beforehand.
class VpTracker {
 public:
  explicit VpTracker(const VpTrackerOptions& options = {});

  // One frame. `directions` are VPs observed in the current camera (any scale, either sign) and
  // R_world_from_camera takes that camera's frame into the odometry frame. `weights` (e.g. the
  // number of supporting segments) default to 1. Returns per observation the id of its track, or
  // -1 when it was ignored:
  //  - non-finite or zero direction, or non-finite or non-positive weight;
  //  - a duplicate: within the association angle of a track that another observation of the
  //    same frame joined (being closer) or started (being heavier); a second track there would
  //    split the VP's later detections and swap ids;
  //  - unmatched while max_tracks tracks exist.
  // Other unmatched observations start new tracks, heaviest first. An invalid rotation (non-finite,
  // not orthonormal within 1e-6, or a reflection) or a weights size other than 0 or
  // directions.size() leaves the tracker untouched and returns all -1.
  std::vector<int> update(const Eigen::Matrix3d& R_world_from_camera,
                          const std::vector<Eigen::Vector3d>& directions,
                          const std::vector<double>& weights = {});

  // Current tracks in order of creation (increasing id).
  const std::vector<VpTrack>& tracks() const { return tracks_; }
  // The track with this id, or nullptr once it is dropped.
  const VpTrack* find(int id) const;

  // Feeds confident tracks to the estimator: for each VP match of the next pair whose d1 (in
  // camera 1, rotated into odometry by R_world_from_camera1) lies within the association angle of
  // a confident track, d1 becomes that track's unit direction in camera 1, signed like the old d1
  // so that sign_known stays true; d2 is kept. One match per track, closest first. Returns per
  // match the id of the track that replaced its d1, or -1 (match unchanged). An invalid rotation
  // changes nothing.
  std::vector<int> refine_matches(const Eigen::Matrix3d& R_world_from_camera1,
                                  std::vector<VpMatch>* matches) const;

  // Drops every track, e.g. when time goes backwards; ids keep increasing.
  void reset() { tracks_.clear(); }

  const VpTrackerOptions& options() const { return options_; }

 private:
  VpTrackerOptions options_;
  std::vector<VpTrack> tracks_;
  int next_id_ = 0;
};

}  // namespace hybrid_vo
