#pragma once

// The map of world directions: the scene's line directions as landmarks at infinity in the
// odometry frame, each with a covariance, and an absolute reference for the camera's rotation
// (LPVO / ManhattanSLAM's drift-free rotation, here from monocular VPs). A direction stays in the
// map while it goes unseen; it is found again by the structure the observed directions form
// (joint association under the predicted orientation and its covariance), not by a small angle.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/direction_map/direction_association.h"
#include "hybrid_vo/direction_map/direction_structure.h"
#include "hybrid_vo/direction_map/joint_orientation.h"

namespace hybrid_vo {

struct DirectionMapOptions {
  // Observations fused before a direction is confirmed and may correct the orientation: clutter
  // rarely recurs in the same direction. And the frames (estimated pairs, each with parallax)
  // between its first and its last observation: a direction is shown fixed over a baseline of
  // motion, as a direction at infinity is and the converging lines of a near object are not.
  int confirm_hits = 3;
  int confirm_frames = 5;
  // How far a direction may drift per frame (degrees, per axis, a random walk): a scene's
  // "directions" are not exactly fixed (a road bends, segments are not straight), and a map that
  // held them rigid would hold the orientation to them.
  double direction_drift_deg = 0.02;
  // An unconfirmed direction unseen for this many frames is forgotten; confirmed ones stay.
  int max_candidate_misses = 30;
  // The map's size; when full, the least supported direction makes room (candidates first).
  int max_directions = 24;
  // New directions start only while the orientation is this certain (largest sigma, degrees):
  // a direction placed under a drifted orientation would be a copy of one the map holds.
  double max_orientation_sigma_deg = 1.5;
  // A new direction must be this far from every direction of the map (degrees) and fail each
  // one's chi-square gate: the white panels' two "horizontal" floor directions, 2-3 degrees apart,
  // are two directions, not one.
  double min_separation_deg = 1.0;
  // A direction's sigma never drops below this (degrees): segments are not exactly straight, nor
  // parallel in the scene, and thousands of fused frames must not make a direction rigid. Kept
  // as the direction's own noise, added to every observation of it.
  double min_direction_sigma_deg = 0.01;
  // An observation without a usable covariance gets this sigma; every one at least the floor.
  double default_sigma_deg = 1.0;
  double min_sigma_deg = 0.005;
  // A confirmed direction is dropped when this many observations in a row fell within
  // disagreement_angle_deg of it yet failed its gate while the orientation was certain, and it
  // fused none of them: its observations no longer agree with it.
  int max_disagreements = 8;
  double disagreement_angle_deg = 3.0;
  // A correction larger than this (degrees) counts as a re-acquisition: beyond what association
  // by a small angle could have found.
  double reacquisition_deg = 3.0;
  // ... and needs two paired directions at least this far apart (degrees). Where the
  // orientation's own covariance pairs fewer than wide_reacquisition_pairs, that many may also be
  // sought under this much more uncertainty (degrees, per axis), for a correction of at most as
  // much. Off (0) by default: a correction is then at most what the chain of pairs since the
  // directions were seen allows by its covariance. The 5 degrees once rescued TartanAir's sure and
  // wrong pairs, but on streets, whose facades lie a few degrees apart, it re-acquired the wrong
  // direction by 4-5 degrees in one frame (doc/consistency.md).
  double reacquisition_min_angle_deg = 30.0;
  double reacquisition_sigma_deg = 0.0;
  int wide_reacquisition_pairs = 3;
  DirectionAssociationOptions association;
  DirectionStructureOptions structure;
};

template <typename Visit>
void visit_fields(DirectionMapOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(non_negative(), o.confirm_frames, o.direction_drift_deg);
  HYBRID_VO_FIELDS(positive(), o.confirm_hits, o.max_candidate_misses, o.max_directions,
                  o.max_orientation_sigma_deg, o.max_disagreements, o.default_sigma_deg,
                  o.wide_reacquisition_pairs);
  HYBRID_VO_FIELDS(non_negative(), o.min_separation_deg, o.min_direction_sigma_deg,
                  o.min_sigma_deg, o.disagreement_angle_deg, o.reacquisition_deg,
                  o.reacquisition_min_angle_deg, o.reacquisition_sigma_deg);
  visit_fields(o.association, prefixed("association_", visit));
  visit_fields(o.structure, prefixed("structure_", visit));
}

struct MapDirection {
  int id = -1;  // stable, never reused
  // Unit, odometry frame, with the sign of its first observation (a direction has none).
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  // rad^2, tangent plane of `direction`: its marginal in the map's joint covariance.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int hits = 0;               // observations fused
  int created = 0;            // the frame it was created in
  int last_seen = -1;         // the frame of its last fused observation
  int disagreements = 0;      // in a row (see max_disagreements)
  int total_disagreements = 0;
  bool confirmed = false;
  double last_chi2 = 0.0;     // of its last paired observation
  double sigma_deg() const;   // sqrt of the covariance's largest eigenvalue
};

// The camera's orientation located in the map, and how each observation was used.
struct MapLocation {
  Eigen::Matrix3d R_world_from_camera = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // left increment, odometry frame
  std::vector<int> direction_id;  // per observation: the map direction it was paired with, or -1
  int paired = 0;                 // observations that corrected the orientation
  double correction_deg = 0.0;
  double joint_chi2 = 0.0;
  bool corrected = false;
  bool pinned = false;      // two of the paired directions are well apart: all three axes fixed
  bool reacquired = false;  // corrected by more than reacquisition_deg
  bool ambiguous = false;   // two associations explained the observations alike: no correction
  bool rejected = false;    // an association was found but failed the joint gate: no correction
  // The joint state after this frame's correction (the prediction when nothing corrected it),
  // and every map direction as corrected with it (the map's order): what update() commits.
  bool has_joint = false;
  JointOrientation joint;
  std::vector<Eigen::Vector3d> directions;
};

struct DirectionMapStats {
  int located = 0;       // frames whose orientation the map corrected
  int reacquisitions = 0;
  int rejected = 0;      // corrections refused: ambiguous or failing the gate
  int created = 0, dropped = 0;
};

// Intended use per frame, with R the odometry's predicted orientation of the current camera and
// `predicted` the joint state grown by the pair (prediction()):
//   MapLocation where = map.locate(R, predicted, vps_seen_in_the_current_image);
//   ... R = where.R_world_from_camera, P = where.covariance ...
//   map.update(R, P, vps_seen_in_the_current_image, where);
// The map holds the joint covariance of the orientation of the last frame it took and its
// directions (joint_orientation.h): a correction updates the orientation and every
// direction together, and the pair's prediction keeps their cross-covariances. The overloads
// that take a bare covariance P of the orientation start from the map's joint state with the
// orientation's covariance set to P (the cross-covariances shrunk if P is smaller).
class DirectionMap {
 public:
  explicit DirectionMap(const DirectionMapOptions& options = {});

  // The orientation of a camera that sees `observations` (camera frame), predicted as R with
  // covariance P: the confirmed directions they pair with, found jointly under P
  // (associate_directions), and R corrected by them. Unchanged where the map cannot decide
  // (nothing paired, ambiguous, or failing the gate). Invalid R or P: unchanged, nothing paired.
  MapLocation locate(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                     const std::vector<VpObservation>& observations) const;
  // `widen`: whether a re-acquisition under a wider uncertainty than the prediction's may be
  // tried (reacquisition_sigma_deg), for an orientation that may be off by more than it says.
  MapLocation locate(const Eigen::Matrix3d& R, const JointOrientation& predicted,
                     const std::vector<VpObservation>& observations, bool widen = true) const;

  // The same with the pairs known (observation i with the direction of id direction_ids[i], -1:
  // none), e.g. from the keyframe's view of the same VPs: the rotation fitted to them, no search.
  MapLocation locate_known(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                           const std::vector<VpObservation>& observations,
                           const std::vector<int>& direction_ids) const;
  MapLocation locate_known(const Eigen::Matrix3d& R, const JointOrientation& predicted,
                           const std::vector<VpObservation>& observations,
                           const std::vector<int>& direction_ids) const;

  // The joint state of the last frame taken, its orientation's covariance set to P (see above);
  // and that state moved by a pair: the orientation's covariance grown by Q (odometry frame),
  // each direction's by its drift.
  JointOrientation prediction(const Eigen::Matrix3d& P) const;
  JointOrientation prediction(const Eigen::Matrix3d& P1, const Eigen::Matrix3d& Q) const;
  const JointOrientation& joint() const { return joint_; }

  // One frame: takes the location's joint state and corrected directions (the paired
  // observations are in them already), fuses the unpaired observations into candidates (which
  // move no orientation), counts disagreements, starts directions from the rest while P is
  // certain, confirms, forgets stale candidates and directions that keep disagreeing, and
  // re-tests the structure. A location without a joint state (default-constructed) takes
  // prediction(P).
  void update(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
              const std::vector<VpObservation>& observations, const MapLocation& location);

  // Priors for a pair's VP matches from the confirmed directions that its d1 pair with under the
  // keyframe's orientation R1 (covariance P1): each direction in camera 1 with its covariance plus
  // the orientation's, signed like d1. Others invalid.
  std::vector<VpPrior> priors(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1,
                              const std::vector<VpMatch>& matches) const;

  const std::vector<MapDirection>& directions() const { return directions_; }
  const MapDirection* find(int id) const;
  // The tested relations between confirmed directions, and the triads and verticals they form.
  const DirectionStructure& structure() const { return structure_; }
  const DirectionMapStats& stats() const { return stats_; }
  int frames() const { return frame_; }
  const DirectionMapOptions& options() const { return options_; }
  // Forgets every direction (ids keep increasing).
  void reset();
  // Observations as the association takes them: unit directions with their covariances, in the
  // camera frame (a missing one the default sigma, each at least the floor); invalid ones are
  // left out and `index` maps back. What ~vanishing_points publishes and the tools check.
  std::vector<VpObservation> usable(const std::vector<VpObservation>& observations,
                                    std::vector<int>* index) const;

 private:
  std::vector<MapLandmark> landmarks(bool confirmed_only) const;
  // Whether two of the association's directions (indices into `confirmed`) are
  // reacquisition_min_angle_deg apart.
  bool spread(const DirectionAssociation& a, const std::vector<int>& confirmed) const;
  // Whether the map holds two confirmed directions that far apart.
  bool pinnable() const;
  MapLocation locate_with(const Eigen::Matrix3d& R, const JointOrientation& predicted,
                          const std::vector<VpObservation>& observations,
                          const std::vector<int>* known_ids, bool widen = true) const;
  // The iterated joint update of the orientation and the directions by the pairs (observation k
  // of `seen` with map direction index j); false when it fails or is implausible.
  bool correct(const Eigen::Matrix3d& R, const std::vector<VpObservation>& seen,
               const std::vector<std::pair<int, int>>& pairs, MapLocation* where) const;
  // Moves direction j to `next`, its joint block re-expressed in the new tangent basis.
  void move_direction(int j, const Eigen::Vector3d& next);
  // Each direction's marginal covariance from the joint state.
  void sync_covariances();
  // A new direction observed at `world` (unit, odometry frame) from the camera at R, whose
  // observation has covariance C (odometry frame, without the orientation's); returns the index
  // of the direction that made room for it, or -1.
  int add_direction(const Eigen::Vector3d& world, const Eigen::Matrix3d& C);
  void remove_direction(int j);
  // A candidate's observation: only its own direction takes the correction.
  void fuse_candidate(int j, const Eigen::Vector3d& world, const Eigen::Matrix3d& C);

  DirectionMapOptions options_;
  std::vector<MapDirection> directions_;
  JointOrientation joint_;  // [orientation of the last frame taken, directions_]
  DirectionStructure structure_;
  DirectionMapStats stats_;
  int next_id_ = 0;
  int frame_ = 0;
};

}  // namespace hybrid_vo
