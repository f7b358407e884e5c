// The visual odometry's orientation: pair rotations chained, anchored by the VP tracks; the VP
// tracker's priors and updates; the rotation rate that predicts the segments' motion.
#include "hybrid_vo/frontend/vo_orientation.h"

#include <cmath>

#include <Eigen/Geometry>

#include "hybrid_vo/frontend/visual_odometry.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/geometry/vp_covariance.h"

namespace hybrid_vo {
namespace {

// The VPs of one image of a pair as tracker observations: each direction with the covariance of
// its fit to that image's labelled segments (pixels, at `sigma_px` per segment) plus `vp_sigma_deg`
// per axis, the pair's measured VP scale: the fit alone is optimistic (rendered corridor: the fit
// says 0.02-0.1 degrees, the VPs are 0.05-0.3 degrees off the true axes).
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
    // Without a usable fit the covariance stays zero: the tracker's default sigma.
    Eigen::Matrix3d covariance;
    if (vp_measurement_covariance(K, segments[k], observations[k].direction, sigma_px,
                                  vp_sigma_deg * M_PI / 180.0, &covariance))
      observations[k].covariance = covariance;
  }
  return observations;
}

// The VPs that the pose `est` accepts, as seen in the current image, each with the covariance
// of its fit to that image's segments at the pair's measured segment noise.
std::vector<VpObservation> inlier_vp_observations(const Eigen::Matrix3d& K,
                                                  const TwoViewMatches& m,
                                                  const RelativePoseEstimate& est) {
  TwoViewMatches inliers;
  inliers.lines = m.lines;
  inliers.line_vp = m.line_vp;
  std::vector<int> kept(m.vps.size(), -1);
  for (size_t k = 0; k < m.vps.size(); ++k) {
    if (k < est.vp_inliers.size() && !est.vp_inliers[k]) continue;
    kept[k] = static_cast<int>(inliers.vps.size());
    inliers.vps.push_back(m.vps[k]);
  }
  for (int& label : inliers.line_vp) label = label >= 0 ? kept[label] : -1;
  return vp_observations(K, inliers, true, est.scales.line_vp_px, est.scales.vp_deg);
}

}  // namespace

VoOrientation::VoOrientation(const VisualOdometryOptions& options)
    : use_tracker_(options.use_vp_tracker),
      anchor_(options.use_vp_tracker && options.anchor_orientation),
      drift_floor_deg_(options.rotation_drift_floor_deg),
      seed_sigma_px_(options.estimator.vp_detection.inlier_threshold_px / 3.0),
      seed_sigma_deg_(options.estimator.ransac.vp_threshold_deg / 3.0),
      tracker_(options.vp_tracker) {}

void VoOrientation::restart() {
  angular_velocity_.setZero();
  tracker_.reset();
  seeded_ = false;
}

void VoOrientation::reset() {
  restart();
  R_wc_.setIdentity();
  covariance_.setZero();
}

Eigen::Matrix3d VoOrientation::segment_motion(const PinholeCamera& camera, double dt) const {
  const Eigen::Vector3d w = angular_velocity_ * dt;
  if (!(w.norm() > 0.0)) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d K = camera.K();
  return K * Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * K.inverse();
}

std::vector<int> VoOrientation::add_vp_priors(const Eigen::Matrix3d& keyframe_R_wc,
                                              const Eigen::Matrix3d& keyframe_K,
                                              TwoViewMatches* m) {
  std::vector<int> track_ids;
  if (!use_tracker_) return track_ids;
  if (!seeded_) {
    tracker_.update(keyframe_R_wc,
                    vp_observations(keyframe_K, *m, false, seed_sigma_px_, seed_sigma_deg_));
    seeded_ = true;
  }
  m->vp_priors = tracker_.priors(keyframe_R_wc, m->vps);
  for (const VpPrior& prior : m->vp_priors) track_ids.push_back(prior.track_id);
  return track_ids;
}

VoOrientation::Oriented VoOrientation::orient(const Eigen::Matrix3d& keyframe_R_wc,
                                              const Eigen::Matrix3d& keyframe_covariance,
                                              const RelativePoseEstimate& est,
                                              const TwoViewMatches& m,
                                              const Eigen::Matrix3d& K) const {
  Oriented o;
  o.pose = est.pose;
  if (use_tracker_) o.seen = inlier_vp_observations(K, m, est);
  o.R_wc = nearest_rotation(keyframe_R_wc * o.pose.R.transpose());
  // The pair's rotation error as a left increment of R (camera 2) is -R_wc times it in the
  // odometry frame.
  const double floor = drift_floor_deg_ * M_PI / 180.0;
  o.covariance = keyframe_covariance + floor * floor * Eigen::Matrix3d::Identity();
  if (est.covariance_valid)
    o.covariance += o.R_wc * est.covariance.topLeftCorner<3, 3>() * o.R_wc.transpose();
  if (!anchor_) return o;
  o.anchoring = tracker_.anchor(o.R_wc, o.covariance, o.seen);
  o.covariance = o.anchoring.covariance;
  // The correction is the drift of earlier pairs, not this pair's motion: the translation stays
  // as this pair's points fixed it (re-fitted under the anchored rotation, it was 37 -> 51 deg
  // off on TUM fr3 structure_notexture).
  if (o.anchoring.anchors > 0) {
    o.R_wc = o.anchoring.R_world_from_camera;
    o.pose.R = nearest_rotation(o.R_wc.transpose() * keyframe_R_wc);
  }
  return o;
}

std::vector<VpAssociation> VoOrientation::advance(const Oriented& oriented,
                                                  const Eigen::Matrix3d& pair_R, double dt) {
  if (dt > 0.0) {
    const Eigen::AngleAxisd turned(pair_R);
    angular_velocity_ = turned.angle() * turned.axis() / dt;
  }
  R_wc_ = oriented.R_wc;
  covariance_ = oriented.covariance;
  // Every estimated frame, also without VPs, so that misses count.
  if (!use_tracker_) return {};
  return tracker_.update(R_wc_, oriented.seen);
}

}  // namespace hybrid_vo
