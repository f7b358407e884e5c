#pragma once

// The camera's orientation in the odometry frame as a Kalman filter: each pair's rotation
// predicts it, its uncertainty growing by the pair's rotation covariance (and much more across a
// blank wall, where the pair's data cannot fix the rotation), and the map of world directions
// corrects it wherever the camera sees them (LPVO's drift-free rotation). The map also judges
// the pair: a rotation that puts the directions the map sees clearly elsewhere is not accepted.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/estimation/translation_given_rotation.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/direction_map/direction_map.h"

namespace hybrid_vo {

struct OrientationFilterOptions {
  DirectionMapOptions map;
  // The map corrects the orientation (else it only gives priors and is kept up to date).
  bool correct = true;
  // Growth of the orientation's uncertainty per pair beyond the pair's covariance (degrees, per
  // axis): no pair is exactly as certain as its inliers say.
  double drift_floor_deg = 0.005;
  // A blank wall: a pair with at most this many segment matches and no VP its pose accepts,
  // whose rotation rests on points alone, which on a plain wall are sensor noise (the rendered
  // corners: 2-6 degrees off per pair, their covariance saying hundredths).
  int blank_wall_max_segments = 15;
  // Its rotation's uncertainty then grows by this (degrees, per axis) plus this fraction of the
  // angle it turned, so that the map can take the directions back after the turn.
  double blank_wall_sigma_deg = 2.0;
  double blank_wall_rotation_fraction = 0.5;
  // Across a blank wall, the rotation of the last motion instead of the pair's (coasting).
  bool coast_blank_walls = false;
  // Where the map corrected the rotation, the pair's translation fitted again under it (points
  // only, relpose_known_rotation_2pt); else the pair's own translation stays.
  bool translation_given_rotation = false;
  // The judge of a pair: its VPs that the keyframe saw as map directions locate the current
  // camera under this much uncertainty of the pair's rotation (degrees, per axis); the pair is
  // rejected when its rotation differs from that location beyond this chi-square (3 dof,
  // 99.9 %).
  double judge_sigma_deg = 10.0;
  double reject_chi2 = 16.27;
  // ... and when the pair's points, re-fitted under the map's rotation (translation only),
  // keep at least this share of the pair's point inliers: on a plane both rotations explain
  // them; where only the pair's does, the VPs are the ones that are wrong.
  double reject_min_inlier_share = 0.5;
  TranslationGivenRotationOptions translation;
};

template <typename Visit>
void visit_fields(OrientationFilterOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(any_value(), o.correct, o.coast_blank_walls, o.translation_given_rotation);
  HYBRID_VO_FIELDS(non_negative(), o.drift_floor_deg, o.blank_wall_max_segments,
                  o.blank_wall_sigma_deg, o.blank_wall_rotation_fraction);
  HYBRID_VO_FIELDS(positive(), o.judge_sigma_deg, o.reject_chi2);
  HYBRID_VO_FIELDS(fraction(), o.reject_min_inlier_share);
  visit_fields(o.map, prefixed("map_", visit));
}

// What the filter needs of a pair (keyframe -> current camera).
struct PairRotation {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // X2 = R X1
  // Of a left increment of R (camera 2's frame), rad^2; zero when unknown.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int segment_matches = 0;
  int vp_inliers = 0;
  // Its rotation rests on no epipolar translation (a rotation alone, rotation_only.h, or a stereo
  // pair's 3D points): its points fix it without the five-point model's ambiguity, so it is no
  // blank wall for want of segments, and the map cannot judge it.
  bool independent_rotation = false;
  // The rotation the camera's last rotation rate gives over this pair's interval, if known.
  bool has_last_motion = false;
  Eigen::Matrix3d last_motion_R = Eigen::Matrix3d::Identity();
  // Every VP of the pair as seen in the current image, and which of them the pose accepts; the
  // same VPs as the keyframe saw them.
  std::vector<VpObservation> vps;
  std::vector<char> vp_accepted;
  std::vector<VpObservation> keyframe_vps;
  // The pair's point matches (pixels, undistorted) and cameras, and its point inliers: to fit
  // the translation again under the map's rotation when the map overrules the pair's.
  const std::vector<PointMatch>* points = nullptr;
  PinholeCamera camera1, camera2;
  int point_inliers = 0;
};

enum class OrientationSource {
  kPair,          // the pair's rotation, the map seeing nothing to correct it with
  kMap,           // corrected by the map's directions
  kReacquired,    // corrected by more than a small angle: directions found again after drift
  kCoasted,       // a blank wall: the last motion's rotation, its uncertainty grown
  kPairRejected,  // the map contradicted the pair's rotation: the map's, t fitted again
};
const char* to_string(OrientationSource source);

struct OrientationEstimate {
  Eigen::Matrix3d R_world_from_camera = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // left increment, odometry frame
  Eigen::Matrix3d predicted_covariance = Eigen::Matrix3d::Zero();  // before the map's correction
  OrientationSource source = OrientationSource::kPair;
  bool blank_wall = false;  // the pair's data could not fix the rotation
  double blank_wall_sigma_rad = 0.0;  // then the uncertainty its rotation got (per axis)
  MapLocation location;     // of the pair's accepted VPs (or of every VP, when rejected)
  std::vector<VpObservation> observations;  // the VPs the map located the camera with
  double correction_deg = 0.0;  // from the pair's prediction
  // The pair's translation fitted again under the map's rotation: kPairRejected, and any
  // correction with translation_given_rotation (refit.ok then).
  TranslationEstimate refit;
};

class OrientationFilter {
 public:
  explicit OrientationFilter(const OrientationFilterOptions& options = {});

  // The current camera's orientation given the keyframe's (R1, covariance P1) and the pair.
  // A non-finite pair rotation or covariance leaves the keyframe's.
  OrientationEstimate estimate(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1,
                               const PairRotation& pair) const;
  // The uncertainty (rad, per axis) a blank wall's pair rotation R gets beyond its covariance.
  double blank_wall_sigma(const Eigen::Matrix3d& R) const;
  // The pair's prediction alone, without the map: its rotation and its covariance grown by it
  // (and by a blank wall's uncertainty when it is one).
  OrientationEstimate predict(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1,
                              const PairRotation& pair) const;
  // Takes the frame into the map (after estimate, with its result).
  void update(const OrientationEstimate& estimate);
  // The map's first directions, from the first keyframe's VPs, seen at R with covariance P.
  void seed(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
            const std::vector<VpObservation>& observations);
  // Priors for the next pair's VP matches (DirectionMap::priors).
  std::vector<VpPrior> priors(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1,
                              const std::vector<VpMatch>& matches) const {
    return map_.priors(R1, P1, matches);
  }
  const DirectionMap& map() const { return map_; }
  const OrientationFilterOptions& options() const { return options_; }
  void reset() { map_.reset(); }

 private:
  // The pair's prediction of the current camera, its covariance and the joint state with the map.
  JointOrientation predict(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1,
                           const PairRotation& pair, double extra_sigma_rad, Eigen::Matrix3d* R,
                           Eigen::Matrix3d* P) const;

  // The map's judgement of the pair (e holds its prediction): whether the pair's VPs that the
  // keyframe saw as two directions of the map, well apart, locate the current camera away from
  // the pair's rotation beyond both covariances, with the pair's points supporting the map's
  // rotation (a plane's points fit a wrong rotation; its VPs do not). Then e is the map's.
  bool judge(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1, const PairRotation& pair,
             double extra_sigma_rad, OrientationEstimate* e) const;
  // The pair's translation fitted under the rotation R2 of the current camera (R1: keyframe's);
  // whether its points support it (reject_min_inlier_share).
  bool refit_translation(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& R2,
                         const PairRotation& pair, TranslationEstimate* refit) const;

  OrientationFilterOptions options_;
  DirectionMap map_;
};

}  // namespace hybrid_vo
