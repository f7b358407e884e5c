// The visual odometry's orientation: pair rotations chained, held by the map of world directions
// (OrientationFilter); the map's priors and seeds; the rotation rate that predicts the segments'
// motion.
#include "hybrid_vo/odometry/vo_orientation.h"

#include <cmath>

#include <Eigen/Geometry>

#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/geometry/vp_covariance.h"
#include "hybrid_vo/odometry/visual_odometry.h"

namespace hybrid_vo {
namespace {

// The VPs of one image of a pair as the map's observations: each direction with the covariance
// of its fit to that image's labelled segments (pixels, at `sigma_px` per segment) plus
// `vp_sigma_deg` per axis, the pair's measured VP scale: the fit alone is optimistic (rendered
// corridor: the fit says 0.02-0.1 degrees, the VPs are 0.05-0.3 degrees off the true axes).
std::vector<VpObservation> vp_observations(const Eigen::Matrix3d& K, const TwoViewMatches& m,
                                           bool second_image, double sigma_px,
                                           double vp_sigma_deg) {
  std::vector<std::vector<LineSegment>> segments(m.vps.size());
  for (size_t i = 0; i < m.lines.size() && i < m.line_vp.size(); ++i)
    if (m.line_vp[i] >= 0 && m.line_vp[i] < static_cast<int>(m.vps.size()))
      segments[m.line_vp[i]].push_back(second_image ? m.lines[i].s2 : m.lines[i].s1);
  std::vector<VpObservation> observations(m.vps.size());
  for (size_t k = 0; k < m.vps.size(); ++k) {
    observations[k].direction = second_image ? m.vps[k].d2 : m.vps[k].d1;
    // Without a usable fit the covariance stays zero: the map's default sigma.
    Eigen::Matrix3d covariance;
    if (vp_measurement_covariance(K, segments[k], observations[k].direction, sigma_px,
                                  vp_sigma_deg * M_PI / 180.0, &covariance))
      observations[k].covariance = covariance;
  }
  return observations;
}

OrientationFilterOptions filter_options(const VisualOdometryOptions& options) {
  OrientationFilterOptions o = options.orientation;
  o.correct = options.anchor_orientation;
  return o;
}

}  // namespace

VoOrientation::VoOrientation(const VisualOdometryOptions& options)
    : use_map_(options.use_direction_map),
      rotation_calibration_sigma_(options.rotation_calibration_sigma),
      full_pair_turn_fraction_(options.full_pair_turn_fraction),
      seed_sigma_px_(options.estimator.vp_detection.inlier_threshold_px / 3.0),
      seed_sigma_deg_(options.estimator.ransac.vp_threshold_deg / 3.0),
      filter_(filter_options(options)) {}

void VoOrientation::restart() {
  angular_velocity_.setZero();
  filter_.reset();
  seeded_ = false;
}

void VoOrientation::reset() {
  restart();
  R_wc_.setIdentity();
  covariance_.setZero();
  sigma_sum_ = variance_sum_ = 0.0;
}

Eigen::Matrix3d VoOrientation::reported_covariance() const {
  const double bound = std::max(0.0, sigma_sum_ * sigma_sum_ - variance_sum_);
  return covariance_ + bound * Eigen::Matrix3d::Identity();
}

Eigen::Matrix3d VoOrientation::segment_motion(const PinholeCamera& camera, double dt) const {
  const Eigen::Vector3d w = angular_velocity_ * dt;
  if (!(w.norm() > 0.0)) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d K = camera.K();
  return K * Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * K.inverse();
}

std::vector<int> VoOrientation::add_vp_priors(const Eigen::Matrix3d& keyframe_R_wc,
                                              const Eigen::Matrix3d& keyframe_covariance,
                                              const Eigen::Matrix3d& keyframe_K,
                                              TwoViewMatches* m) {
  std::vector<int> direction_ids;
  if (!use_map_) return direction_ids;
  if (!seeded_) {
    filter_.seed(keyframe_R_wc, keyframe_covariance,
                 vp_observations(keyframe_K, *m, false, seed_sigma_px_, seed_sigma_deg_));
    seeded_ = true;
  }
  m->vp_priors = filter_.priors(keyframe_R_wc, keyframe_covariance, m->vps);
  for (const VpPrior& prior : m->vp_priors) direction_ids.push_back(prior.track_id);
  return direction_ids;
}

VoOrientation::Oriented VoOrientation::orient(const Eigen::Matrix3d& keyframe_R_wc,
                                              const Eigen::Matrix3d& keyframe_covariance,
                                              const Pair& pair) const {
  const RelativePoseEstimate& est = *pair.estimate;
  const TwoViewMatches& m = *pair.matches;
  PairRotation rotation;
  rotation.R = est.pose.R;
  // A pose whose curvature gave no covariance (its data do not fix it) is as uncertain as a
  // blank wall's, not certain.
  const double unknown = est.covariance_valid ? 0.0 : filter_.blank_wall_sigma(est.pose.R);
  rotation.covariance = est.covariance_valid ? Eigen::Matrix3d(est.covariance.topLeftCorner<3, 3>())
                                             : Eigen::Matrix3d(unknown * unknown *
                                                               Eigen::Matrix3d::Identity());
  rotation.segment_matches = static_cast<int>(m.lines.size());
  rotation.vp_inliers = est.num_vp_inliers;
  rotation.independent_rotation = pair.independent_rotation;
  if (pair.dt > 0.0) {
    const Eigen::Vector3d w = angular_velocity_ * pair.dt;
    rotation.has_last_motion = true;
    rotation.last_motion_R = w.norm() > 0.0 ? rotation_about(w.normalized(), w.norm())
                                            : Eigen::Matrix3d::Identity();
  }
  Oriented o;
  o.pose = o.scale_pose = est.pose;
  if (!use_map_ || !pair.vps_detected) {
    o.estimate = filter_.predict(keyframe_R_wc, keyframe_covariance, rotation);
  } else {
    // Each VP with the covariance of its fit to the segments at the pair's measured noise.
    rotation.vps = vp_observations(pair.camera.K(), m, true, est.scales.line_vp_px,
                                   est.scales.vp_deg);
    rotation.vp_accepted = est.vp_inliers;
    rotation.keyframe_vps = vp_observations(pair.keyframe_camera.K(), m, false,
                                            est.scales.line_vp_px, est.scales.vp_deg);
    rotation.points = &m.points;
    rotation.camera1 = pair.keyframe_camera;
    rotation.camera2 = pair.camera;
    rotation.point_inliers = est.num_point_inliers;
    o.estimate = filter_.estimate(keyframe_R_wc, keyframe_covariance, rotation);
  }
  o.R_wc = o.estimate.R_world_from_camera;
  o.covariance = o.estimate.covariance;
  // A correction is the drift of earlier pairs, not this pair's motion: the motion stays as this
  // pair's points fixed it, rotation and translation (the translation re-fitted under the
  // anchored rotation was 37 -> 51 deg off on TUM fr3 structure_notexture), and the map's share
  // goes to the orientation only: the pairs keep the fast part, the map adds the slow one. A
  // rejected pair's rotation was wrong: its translation was fitted again under the map's (as
  // every corrected pair's is with translation_given_rotation), and that pose also scales the
  // motion; a coasted pair moves by the last rate.
  const OrientationSource source = o.estimate.source;
  if (source == OrientationSource::kPairRejected || source == OrientationSource::kCoasted ||
      o.estimate.refit.ok)
    o.pose.R = nearest_rotation(o.R_wc.transpose() * keyframe_R_wc);
  if (o.estimate.refit.ok) o.pose.t = o.estimate.refit.pose.t;
  if (source == OrientationSource::kPairRejected) o.scale_pose = o.pose;
  const double blank = std::hypot(o.estimate.blank_wall_sigma_rad, unknown);
  const Eigen::AngleAxisd turned(o.pose.R);
  const Eigen::Vector3d w = turned.angle() * turned.axis();
  const double c = rotation_calibration_sigma_,
               k = pair.independent_rotation ? 0.0 : full_pair_turn_fraction_;
  o.motion_rotation_extra =
      (blank * blank + (c * c + k * k) * w.squaredNorm()) * Eigen::Matrix3d::Identity();
  return o;
}

void VoOrientation::accumulate(const Oriented& oriented,
                               const Eigen::Matrix3d& motion_rotation_covariance,
                               double* sigma_sum, double* variance_sum) const {
  *sigma_sum = sigma_sum_;
  *variance_sum = variance_sum_;
  const double variance = std::max(0.0, motion_rotation_covariance.trace() / 3.0);
  if (std::isfinite(variance)) {
    *sigma_sum += std::sqrt(variance);
    *variance_sum += variance;
  }
  // The map's correction shrank the filter's uncertainty by a share: the excess shrinks alike
  // (sigma_sum^2 - variance_sum scales with it).
  const double before = oriented.estimate.predicted_covariance.trace();
  const double share = before > 0.0 ? oriented.covariance.trace() / before : 1.0;
  if (std::isfinite(share) && share < 1.0) {
    *sigma_sum *= std::sqrt(std::max(0.0, share));
    *variance_sum *= std::max(0.0, share);
  }
}

Eigen::Matrix3d VoOrientation::reported_covariance(
    const Oriented& oriented, const Eigen::Matrix3d& motion_rotation_covariance) const {
  double sigma_sum = 0.0, variance_sum = 0.0;
  accumulate(oriented, motion_rotation_covariance, &sigma_sum, &variance_sum);
  const double bound = std::max(0.0, sigma_sum * sigma_sum - variance_sum);
  return oriented.covariance + bound * Eigen::Matrix3d::Identity();
}

void VoOrientation::set_rate(const Eigen::Matrix3d& R, double dt) {
  if (!(dt > 0.0) || !all_finite(R)) return;
  const Eigen::AngleAxisd turned(R);
  angular_velocity_ = turned.angle() * turned.axis() / dt;
}

void VoOrientation::advance(const Oriented& oriented, double dt,
                            const Eigen::Matrix3d& motion_rotation_covariance) {
  // A coasted pair keeps the last rate: its own rotation is what could not be trusted.
  if (oriented.estimate.source != OrientationSource::kCoasted)
    set_rate(oriented.scale_pose.R, dt);
  accumulate(oriented, motion_rotation_covariance, &sigma_sum_, &variance_sum_);
  R_wc_ = oriented.R_wc;
  covariance_ = oriented.covariance;
  // Without the map too: the filter carries the rotation scale's share of the orientation.
  filter_.update(oriented.estimate);
}

}  // namespace hybrid_vo
