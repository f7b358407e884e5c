// The orientation filter: the map's judgement of a pair (a plane's points fit a wrong rotation, its
// VPs do not; VPs that only the points contradict are the wrong ones), blank walls, the prediction
// without the map.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/geometry/rotation.h"
#include "hybrid_vo/direction_map/orientation_filter.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = M_PI / 180.0;
const std::vector<Eigen::Vector3d> kTriad = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                             Eigen::Vector3d::UnitZ()};
const PinholeCamera kCamera(500.0, 500.0, 320.0, 240.0);

double angle_deg(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return Eigen::AngleAxisd(A * B.transpose()).angle() / kDeg;
}

// The world's directions as VPs of a camera R (world from camera), 0.3 degrees certain.
std::vector<VpObservation> vps_of(const Eigen::Matrix3d& R) {
  std::vector<VpObservation> out;
  for (const Eigen::Vector3d& d : kTriad) {
    VpObservation o;
    o.direction = R.transpose() * d;
    o.covariance = std::pow(0.3 * kDeg, 2) *
                   (Eigen::Matrix3d::Identity() - o.direction * o.direction.transpose());
    out.push_back(o);
  }
  return out;
}

// A filter whose map holds the triad, seen by 6 frames of known orientation (a direction is
// confirmed once seen 5 frames after its first sighting).
OrientationFilter filter_with_triad() {
  OrientationFilter filter;
  const Eigen::Matrix3d P = std::pow(0.01 * kDeg, 2) * Eigen::Matrix3d::Identity();
  for (int k = 0; k < 6; ++k) {
    const Eigen::Matrix3d R = rotation_about(Eigen::Vector3d(0.1, 1, 0.2).normalized(), 0.02 * k);
    OrientationEstimate e;
    e.R_world_from_camera = R;
    e.covariance = P;
    e.observations = vps_of(R);
    e.location = filter.map().locate(R, P, e.observations);
    filter.update(e);
  }
  return filter;
}

// Points 5 m ahead of camera 1 (on a plane, else 3-8 m deep) seen by both cameras of the motion
// X2 = R X1 + t, with half a pixel of noise.
std::vector<PointMatch> scene_points(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                     bool plane) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::vector<PointMatch> points;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d X(u(rng), u(rng), plane ? 5.0 : 5.5 + 1.25 * u(rng));
    const Eigen::Vector3d Y = R * X + t;
    PointMatch m;
    m.x1 = kCamera.denormalize(X.head<2>() / X.z()) + Eigen::Vector2d(noise(rng), noise(rng));
    m.x2 = kCamera.denormalize(Y.head<2>() / Y.z()) + Eigen::Vector2d(noise(rng), noise(rng));
    points.push_back(m);
  }
  return points;
}

struct Judged {
  OrientationEstimate estimate;
  Eigen::Matrix3d truth;  // the current camera's orientation
  Eigen::Vector3d t_true;
};

// The pair from R1 to a camera turned 3 degrees, whose pose is 6 degrees off the truth. With
// `points_follow_the_pose`, the points of a deep scene were made by that wrong pose (the VPs are
// then the ones that disagree with the scene), else those of a plane by the true motion (a plane
// fits both).
Judged judge_a_wrong_pair(bool points_follow_the_pose, std::vector<PointMatch>* points) {
  static const OrientationFilter filter = filter_with_triad();
  const Eigen::Matrix3d R1 = rotation_about(Eigen::Vector3d(0.1, 1, 0.2).normalized(), 0.1);
  const Eigen::Matrix3d R_true = rotation_about(Eigen::Vector3d::UnitY(), 3.0 * kDeg);  // X2 = R X1
  const Eigen::Matrix3d R_wrong =
      rotation_about(Eigen::Vector3d(1, 0.3, 0).normalized(), 6.0 * kDeg) * R_true;
  const Eigen::Vector3d t(0.3, 0.0, 0.1);
  Judged j;
  j.truth = R1 * R_true.transpose();
  j.t_true = t.normalized();
  *points = points_follow_the_pose ? scene_points(R_wrong, t, false)
                                   : scene_points(R_true, t, true);
  PairRotation pair;
  pair.R = R_wrong;
  pair.covariance = std::pow(0.05 * kDeg, 2) * Eigen::Matrix3d::Identity();
  pair.segment_matches = 30;
  pair.vp_inliers = 0;
  pair.vps = vps_of(j.truth);
  pair.vp_accepted.assign(pair.vps.size(), 0);
  pair.keyframe_vps = vps_of(R1);
  pair.points = points;
  pair.camera1 = pair.camera2 = kCamera;
  pair.point_inliers = 180;
  j.estimate = filter.estimate(R1, std::pow(0.05 * kDeg, 2) * Eigen::Matrix3d::Identity(), pair);
  return j;
}

TEST(OrientationFilter, AMapThatSeesThePlanesVpsOverrulesItsWrongRotation) {
  std::vector<PointMatch> points;
  const Judged j = judge_a_wrong_pair(false, &points);
  ASSERT_EQ(j.estimate.source, OrientationSource::kPairRejected);
  EXPECT_LT(angle_deg(j.estimate.R_world_from_camera, j.truth), 0.3);
  EXPECT_NEAR(j.estimate.correction_deg, 6.0, 0.5);
  ASSERT_TRUE(j.estimate.refit.ok);
  EXPECT_GE(j.estimate.refit.num_inliers, 150);
  EXPECT_LT(translation_error(j.estimate.refit.pose.t, j.t_true) / kDeg, 3.0);
}

TEST(OrientationFilter, VpsThatOnlyThePointsContradictDoNotOverrule) {
  std::vector<PointMatch> points;
  const Judged j = judge_a_wrong_pair(true, &points);
  EXPECT_NE(j.estimate.source, OrientationSource::kPairRejected);
  EXPECT_FALSE(j.estimate.refit.ok);
}

TEST(OrientationFilter, BlankWallsGrowTheUncertaintyAndNeedNoMap) {
  const OrientationFilter filter;
  PairRotation pair;
  pair.R = rotation_about(Eigen::Vector3d::UnitY(), 4.0 * kDeg);
  pair.covariance = std::pow(0.02 * kDeg, 2) * Eigen::Matrix3d::Identity();
  pair.segment_matches = 2;
  const Eigen::Matrix3d P1 = std::pow(0.1 * kDeg, 2) * Eigen::Matrix3d::Identity();
  const OrientationEstimate blank = filter.estimate(Eigen::Matrix3d::Identity(), P1, pair);
  EXPECT_TRUE(blank.blank_wall);
  // 2 degrees plus half the 4 degrees turned, per axis.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(blank.covariance);
  EXPECT_GT(std::sqrt(eigen.eigenvalues().minCoeff()) / kDeg, 2.7);
  EXPECT_EQ(blank.source, OrientationSource::kPair);
  EXPECT_LT(angle_deg(blank.R_world_from_camera, pair.R.transpose()), 1e-9);

  pair.segment_matches = 40;  // many segments: the rotation is not the points' alone
  EXPECT_FALSE(filter.estimate(Eigen::Matrix3d::Identity(), P1, pair).blank_wall);
  pair.segment_matches = 2;
  pair.vp_inliers = 1;  // a VP accepted: not blank either
  EXPECT_FALSE(filter.estimate(Eigen::Matrix3d::Identity(), P1, pair).blank_wall);

  // Coasting carries it on the last motion's rotation instead.
  OrientationFilterOptions coasting;
  coasting.coast_blank_walls = true;
  pair.vp_inliers = 0;
  pair.has_last_motion = true;
  pair.last_motion_R = rotation_about(Eigen::Vector3d::UnitY(), 1.0 * kDeg);
  const OrientationEstimate coasted =
      OrientationFilter(coasting).estimate(Eigen::Matrix3d::Identity(), P1, pair);
  EXPECT_EQ(coasted.source, OrientationSource::kCoasted);
  EXPECT_LT(angle_deg(coasted.R_world_from_camera, pair.last_motion_R.transpose()), 1e-9);
}

TEST(OrientationFilter, BadInputLeavesThePrediction) {
  const OrientationFilter filter = filter_with_triad();
  PairRotation pair;
  pair.R = Eigen::Matrix3d::Identity();
  pair.R(0, 0) = std::numeric_limits<double>::quiet_NaN();
  pair.segment_matches = 30;
  pair.vps = vps_of(Eigen::Matrix3d::Identity());
  pair.vp_accepted.assign(3, 1);
  const OrientationEstimate e =
      filter.estimate(Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Zero(), pair);
  EXPECT_EQ(e.source, OrientationSource::kPair);
  EXPECT_EQ(e.location.paired, 0);
  EXPECT_TRUE(e.R_world_from_camera.isApprox(Eigen::Matrix3d::Identity()));
}

}  // namespace
}  // namespace hybrid_vo
