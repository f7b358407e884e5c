#include "hybrid_vo/direction_map/orientation_filter.h"

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;

double angle_deg(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return Eigen::AngleAxisd(A * B.transpose()).angle() / kDeg;
}

}  // namespace

const char* to_string(OrientationSource source) {
  switch (source) {
    case OrientationSource::kPair:
      return "pair";
    case OrientationSource::kMap:
      return "map";
    case OrientationSource::kReacquired:
      return "re-acquired";
    case OrientationSource::kCoasted:
      return "coasted";
    case OrientationSource::kPairRejected:
      return "pair rejected";
  }
  return "unknown";
}

OrientationFilter::OrientationFilter(const OrientationFilterOptions& options)
    : options_(options), map_(options.map) {}

JointOrientation OrientationFilter::predict(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1,
                                            const PairRotation& pair, double extra_sigma_rad,
                                            Eigen::Matrix3d* R, Eigen::Matrix3d* P) const {
  *R = nearest_rotation(R1 * pair.R.transpose());
  const double floor = options_.drift_floor_deg * kDeg;
  Eigen::Matrix3d Q =
      (floor * floor + extra_sigma_rad * extra_sigma_rad) * Eigen::Matrix3d::Identity();
  // The pair's error as a left increment of R (camera 2) is -R_wc times it in the odometry frame.
  if (all_finite(pair.covariance)) Q += *R * pair.covariance * R->transpose();
  const JointOrientation joint = map_.prediction(P1, 0.5 * (Q + Q.transpose()));
  *P = joint.orientation();
  return joint;
}

double OrientationFilter::blank_wall_sigma(const Eigen::Matrix3d& R) const {
  const double turned = Eigen::AngleAxisd(nearest_rotation(R)).angle();
  return std::hypot(options_.blank_wall_sigma_deg * kDeg,
                    options_.blank_wall_rotation_fraction * turned);
}

OrientationEstimate OrientationFilter::predict(const Eigen::Matrix3d& R1,
                                               const Eigen::Matrix3d& P1,
                                               const PairRotation& pair) const {
  OrientationEstimate e;
  e.R_world_from_camera = R1;
  e.covariance = P1;
  if (!all_finite(pair.R) || !all_finite(R1) || !all_finite(P1)) return e;
  // A blank wall is the pair's, map or not.
  e.blank_wall = !pair.independent_rotation &&
                 pair.segment_matches <= options_.blank_wall_max_segments && pair.vp_inliers == 0;
  e.blank_wall_sigma_rad = e.blank_wall ? blank_wall_sigma(pair.R) : 0.0;
  e.location.joint =
      predict(R1, P1, pair, e.blank_wall_sigma_rad, &e.R_world_from_camera, &e.covariance);
  e.predicted_covariance = e.covariance;
  e.location.has_joint = true;
  for (const MapDirection& d : map_.directions()) e.location.directions.push_back(d.direction);
  return e;
}

OrientationEstimate OrientationFilter::estimate(const Eigen::Matrix3d& R1,
                                                const Eigen::Matrix3d& P1,
                                                const PairRotation& pair) const {
  OrientationEstimate e;
  e.R_world_from_camera = R1;  // a non-finite input: nothing of the pair is taken
  e.covariance = P1;
  if (!all_finite(pair.R) || !all_finite(R1) || !all_finite(P1)) return e;
  e.blank_wall = !pair.independent_rotation &&
                 pair.segment_matches <= options_.blank_wall_max_segments && pair.vp_inliers == 0;
  const double extra = e.blank_wall ? blank_wall_sigma(pair.R) : 0.0;
  e.blank_wall_sigma_rad = extra;
  PairRotation coasted;
  const bool coast = e.blank_wall && options_.coast_blank_walls && pair.has_last_motion;
  if (coast) {
    coasted = pair;
    coasted.R = pair.last_motion_R;
  }
  Eigen::Matrix3d predicted, P;
  const JointOrientation joint = predict(R1, P1, coast ? coasted : pair, extra, &predicted, &P);
  if (!all_finite(predicted) || !all_finite(P)) return e;
  e.R_world_from_camera = predicted;
  e.covariance = e.predicted_covariance = P;
  if (coast) e.source = OrientationSource::kCoasted;

  if (options_.correct && judge(R1, P1, pair, extra, &e)) return e;

  for (size_t k = 0; k < pair.vps.size(); ++k)
    if (k >= pair.vp_accepted.size() || pair.vp_accepted[k])
      e.observations.push_back(pair.vps[k]);
  // A pair whose rotation its own points pin (independent_rotation) leaves the orientation as
  // good as the keyframe's, and says so: no reason to widen it for a re-acquisition, which on
  // pans over facades took oblique directions for the map's and moved exact pairs by degrees.
  e.location = map_.locate(e.R_world_from_camera, joint, e.observations,
                           !pair.independent_rotation);
  if (!options_.correct || !e.location.corrected) {
    // The prediction is what the map takes; its pairings still count as sightings.
    e.location.has_joint = true;
    e.location.joint = joint;
    e.location.directions.clear();
    for (const MapDirection& d : map_.directions()) e.location.directions.push_back(d.direction);
    return e;
  }
  e.R_world_from_camera = e.location.R_world_from_camera;
  e.covariance = e.location.covariance;
  e.source = e.location.reacquired ? OrientationSource::kReacquired : OrientationSource::kMap;
  e.correction_deg = angle_deg(e.R_world_from_camera, predicted);
  if (options_.translation_given_rotation &&
      !refit_translation(R1, e.R_world_from_camera, pair, &e.refit))
    e.refit = TranslationEstimate();
  return e;
}

bool OrientationFilter::judge(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& P1,
                              const PairRotation& pair, double extra_sigma_rad,
                              OrientationEstimate* e) const {
  // A rotation fixed without an epipolar translation (a rotation alone, stereo 3D points) is
  // pinned by its points (no plane's second motion, no translation to trade it for): nothing for
  // the map to overrule.
  if (pair.independent_rotation) return false;
  if (pair.vps.size() < 2 || pair.keyframe_vps.size() != pair.vps.size()) return false;
  // Only a pair whose pose refuses a VP that the keyframe saw as a direction of the map.
  const MapLocation before = map_.locate(R1, P1, pair.keyframe_vps);
  bool refused = false;
  for (size_t k = 0; k < pair.vps.size() && k < pair.vp_accepted.size(); ++k)
    refused = refused || (before.direction_id[k] >= 0 && !pair.vp_accepted[k]);
  if (!before.pinned || !refused) return false;
  // Those VPs, with the keyframe's pairs, locate the current camera while hardly trusting the
  // pair's rotation.
  Eigen::Matrix3d R_loose, P_loose;
  const JointOrientation loose =
      predict(R1, P1, pair, std::max(extra_sigma_rad, options_.judge_sigma_deg * kDeg), &R_loose,
              &P_loose);
  const MapLocation judged = map_.locate_known(R_loose, loose, pair.vps, before.direction_id);
  if (!judged.pinned) return false;
  const Eigen::Matrix3d predicted = e->R_world_from_camera;
  const Eigen::AngleAxisd apart(judged.R_world_from_camera * predicted.transpose());
  const Eigen::Vector3d delta = apart.angle() * apart.axis();
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(e->covariance + judged.covariance);
  if (!lu.isInvertible() || !(delta.dot(lu.inverse() * delta) > options_.reject_chi2))
    return false;
  TranslationEstimate refit;
  if (!refit_translation(R1, judged.R_world_from_camera, pair, &refit)) return false;
  e->source = OrientationSource::kPairRejected;
  e->refit = refit;
  e->R_world_from_camera = judged.R_world_from_camera;
  e->covariance = judged.covariance;
  e->location = judged;
  e->observations = pair.vps;
  e->correction_deg = angle_deg(e->R_world_from_camera, predicted);
  return true;
}

bool OrientationFilter::refit_translation(const Eigen::Matrix3d& R1, const Eigen::Matrix3d& R2,
                                          const PairRotation& pair,
                                          TranslationEstimate* refit) const {
  if (!pair.points) return false;
  // X2 = R X1 with R_wc2 = R_wc1 R^T.
  const Eigen::Matrix3d R = nearest_rotation(R2.transpose() * R1);
  *refit = estimate_translation_given_rotation(pair.camera1, pair.camera2, *pair.points, R,
                                               options_.translation);
  return refit->ok &&
         refit->num_inliers >= options_.reject_min_inlier_share * pair.point_inliers;
}

void OrientationFilter::update(const OrientationEstimate& estimate) {
  map_.update(estimate.R_world_from_camera, estimate.covariance, estimate.observations,
              estimate.location);
}

void OrientationFilter::seed(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                             const std::vector<VpObservation>& observations) {
  map_.update(R, P, observations, map_.locate(R, P, observations));
}

}  // namespace hybrid_vo
