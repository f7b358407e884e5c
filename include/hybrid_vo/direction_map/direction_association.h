#pragma once

// Which map directions a camera's observed VPs are, and the camera's rotation they give: joint
// compatibility branch and bound (Neira and Tardos 2001) on the sphere. Each hypothesis pairs
// some observations with distinct map directions; an iterated Kalman update under the predicted
// orientation's covariance fits the rotation to them, and the hypothesis is kept when the pairs
// and the correction are jointly plausible. The most pairs win, then the lowest joint
// chi-square. With a certain prediction this is association by a small angle; with a grown one
// (a blank wall crossed) the discrete symmetries of the structure compete, and the prediction's
// covariance picks one, or none when two explain the observations alike.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/geometry/option_fields.h"

namespace hybrid_vo {

// One VP seen in a camera.
struct VpObservation {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // camera frame, any scale or sign
  // Covariance of the unit direction in the camera frame (rad^2, tangent plane), e.g. from its
  // segments (vp_measurement_covariance). Zero: the consumer's default sigma.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

// A direction of the map as the association sees it (odometry frame).
struct MapLandmark {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  // unit
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // rad^2, tangent plane
};

struct DirectionAssociationOptions {
  // An observation is a candidate for a direction within this chi-square (2 dof; 99.9 %:
  // generous, as it is linearised at the prediction); a hypothesis must pass the joint test at
  // 99 % for its 2 k + 0 degrees of freedom.
  double candidate_chi2 = 13.82;
  // A hypothesis leads when the next one with as many pairs and a rotation more than
  // ambiguity_min_deg away has a joint chi-square this much larger (a likelihood ratio of ~90).
  double ambiguity_chi2 = 9.0;
  double ambiguity_min_deg = 0.5;
  // At most this many candidates per observation, nearest first, and observations considered.
  int max_candidates = 6;
  int max_observations = 8;
  // Hypotheses evaluated at most; a search that needs more pairs nothing (counted as ambiguous):
  // a frame's handful of VPs takes a few dozen.
  int max_hypotheses = 5000;
};

template <typename Visit>
void visit_fields(DirectionAssociationOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(positive(), o.candidate_chi2, o.max_candidates, o.max_observations,
                  o.max_hypotheses);
  HYBRID_VO_FIELDS(non_negative(), o.ambiguity_chi2, o.ambiguity_min_deg);
}

struct DirectionAssociation {
  std::vector<int> landmark;  // per observation: index into the landmarks, or -1
  int paired = 0;
  // The rotation corrected by the pairs: R_world_from_camera = exp(delta) R, its covariance.
  Eigen::Matrix3d R_world_from_camera = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double joint_chi2 = 0.0;
  bool ambiguous = false;  // another hypothesis explained the observations alike: none paired
  int candidates = 0;      // observations with at least one candidate direction
  int hypotheses = 0;      // evaluated
};

// `observations` are unit directions in the camera, each with a tangent covariance; R predicts
// the camera's orientation (world from camera) with covariance P (left increment, world frame).
// Without a plausible, unambiguous hypothesis nothing is paired and R, P come back unchanged.
DirectionAssociation associate_directions(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                          const std::vector<VpObservation>& observations,
                                          const std::vector<MapLandmark>& landmarks,
                                          const DirectionAssociationOptions& options = {});

// The rotation fitted to known pairs, observation i with landmark pairing[i] (-1: none), without
// a search: nothing is paired when they are jointly implausible under the prediction.
DirectionAssociation fit_directions(const Eigen::Matrix3d& R, const Eigen::Matrix3d& P,
                                    const std::vector<VpObservation>& observations,
                                    const std::vector<MapLandmark>& landmarks,
                                    const std::vector<int>& pairing);

// An observed direction (odometry frame, unit) against a map direction (unit): the observation's
// azimuthal equidistant coordinates in the direction's tangent plane (tangent_basis), either sign,
// and their Jacobian with respect to a left rotation increment applied to the observation. False
// beyond 90 degrees (not this direction).
bool direction_residual(const Eigen::Vector3d& world, const Eigen::Vector3d& direction,
                        Eigen::Vector2d* r, Eigen::Matrix<double, 2, 3>* H);

// The 99 % quantile of the chi-square distribution with `dof` degrees of freedom.
double chi2_quantile_99(int dof);

}  // namespace hybrid_vo
