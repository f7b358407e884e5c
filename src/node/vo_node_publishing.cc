// The node's outputs of the motion: ~relative_pose, tf, ~odometry, ~path and ~vanishing_points
// (DESIGN.md, "The node"; as viso2_ros's odometer base class publishes tf and odometry).
#include <algorithm>

#include <Eigen/Geometry>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <hybrid_vo/MotionEstimate.h>
#include <hybrid_vo/VanishingPoints.h>
#include <nav_msgs/Odometry.h>
#include <tf2_eigen/tf2_eigen.h>

#include "hybrid_vo/geometry/pose_covariance.h"
#include "hybrid_vo/node/conversions.h"
#include "hybrid_vo/node/vo_node.h"

namespace hybrid_vo {
namespace {

uint8_t status_code(const VisualOdometryResult& r) {
  switch (r.status) {
    case VoStatus::kOk:
    case VoStatus::kRotationOnly:
      return MotionEstimate::STATUS_OK;
    case VoStatus::kInvalidInput:
      return MotionEstimate::STATUS_INVALID_INPUT;
    case VoStatus::kTooFewFeatures:
      return MotionEstimate::STATUS_TOO_LITTLE_DATA;
    case VoStatus::kNoPose:
      switch (r.estimate.estimate.status) {
        case EstimationStatus::kTooLittleData:
          return MotionEstimate::STATUS_TOO_LITTLE_DATA;
        case EstimationStatus::kDegenerate:
          return MotionEstimate::STATUS_DEGENERATE;
        default:
          return MotionEstimate::STATUS_NO_MODEL;
      }
    default:
      return MotionEstimate::STATUS_SKIPPED;
  }
}

// Matches, inliers, solver statistics and timings of a frame, into its message.
void fill_statistics(const VisualOdometryResult& result, bool moved, int map_directions,
                     MotionEstimate* rel) {
  const RelativePoseEstimate& est = result.estimate.estimate;
  rel->points = result.num_point_matches;
  rel->lines = result.num_line_matches;
  rel->point_inliers = est.num_point_inliers;
  rel->line_inliers = est.num_line_inliers;
  rel->junctions = est.junctions.size();
  rel->junction_inliers = est.num_junction_inliers;
  rel->vps = result.matches.vps.size();
  rel->vp_inliers = est.num_vp_inliers;
  const OrientationEstimate& o = result.orientation;
  switch (o.source) {
    case OrientationSource::kPair:
      rel->orientation_source = MotionEstimate::ORIENTATION_PAIR;
      break;
    case OrientationSource::kMap:
      rel->orientation_source = MotionEstimate::ORIENTATION_MAP;
      break;
    case OrientationSource::kReacquired:
      rel->orientation_source = MotionEstimate::ORIENTATION_REACQUIRED;
      break;
    case OrientationSource::kCoasted:
      rel->orientation_source = MotionEstimate::ORIENTATION_COASTED;
      break;
    case OrientationSource::kPairRejected:
      rel->orientation_source = MotionEstimate::ORIENTATION_PAIR_REJECTED;
      break;
  }
  rel->map_directions_seen = o.location.paired;
  rel->map_directions = map_directions;
  rel->orientation_correction_deg = o.correction_deg;
  rel->blank_wall = o.blank_wall;
  rel->map_correction_rejected = o.location.ambiguous || o.location.rejected;
  for (const SolverInfo& info : solver_table()) {
    const SolverStatistics& s = est.solvers[static_cast<int>(info.id)];
    if (s.sampled == 0) continue;
    rel->solvers.push_back(info.code);
    rel->solver_sampled.push_back(s.sampled);
    rel->solver_best.push_back(s.best);
  }
  if (moved) rel->best_solver = solver_info(est.best_solver).code;
  rel->iterations = est.iterations;
  rel->frontend_ms = result.frontend_ms;
  rel->estimator_ms = result.estimator_ms;
  rel->total_ms = result.total_ms;
  rel->points_ms = result.stages.points_ms;
  rel->redetect_ms = result.stages.redetect_ms;
  rel->lines_ms = result.stages.lines_ms;
  rel->line_matching_ms = result.stages.line_matching_ms;
  rel->vps_ms = result.stages.vps_ms;
  rel->ransac_ms = result.stages.ransac_ms;
  rel->stereo_ms = result.stages.stereo_ms;
}

}  // namespace

void VoNode::publish(const Frame& frame, const VisualOdometryInput& input,
                     const VisualOdometryResult& result, bool lost) {
  camera_frame_ = frame.frame_id;
  publish_relative_pose(frame, result, lost);
  if (answered(result.status)) publish_pose(frame.stamp, frame.frame_id, result, lost);
  publish_vanishing_points(frame.stamp, result);
  if (params_.publish_markers && markers_pub_.getNumSubscribers() > 0)
    publish_markers(frame.stamp, input, result);
  if (params_.publish_debug_image && debug_image_pub_.getNumSubscribers() > 0)
    publish_debug_image(frame, input, result);
}

void VoNode::publish_relative_pose(const Frame& frame, const VisualOdometryResult& result,
                                   bool lost) {
  MotionEstimate rel;
  rel.header.stamp = frame.stamp;
  rel.header.frame_id = frame.frame_id;
  rel.reference_stamp = ros::Time(result.reference_stamp);
  rel.reference_frame_id = frame.frame_id;
  rel.status = status_code(result);
  const std::string& message = lost ? monitor_.description() : result.message;
  rel.status_text =
      std::string(to_string(result.status)) + (message.empty() ? "" : ": " + message);
  const bool moved = result.status == VoStatus::kOk || result.status == VoStatus::kRotationOnly;
  rel.rotation_only = result.status == VoStatus::kRotationOnly;
  rel.parallax_px = result.parallax_px;
  rel.baseline = moved && result.baseline;
  rel.transform = moved ? to_transform(result.motion.R, result.motion.t)
                        : to_transform(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  rel.scale_known = moved && result.scale_known;
  if (moved && result.motion_covariance_valid) {
    // The estimator's covariance for the translation as published, with a stereo scale's
    // uncertainty along t.
    for (int i = 0; i < 36; ++i) rel.covariance[i] = result.motion_covariance(i / 6, i % 6);
  }
  int confirmed = 0;
  for (const MapDirection& d : vo_->direction_map().directions()) confirmed += d.confirmed;
  fill_statistics(result, moved, confirmed, &rel);
  relative_pose_pub_.publish(rel);
}

void VoNode::look_up_base_transform(const std::string& camera_frame) {
  // The body frame sits at the camera through a (static) transform; odom starts at the body.
  looked_up_base_ = true;
  try {
    const geometry_msgs::TransformStamped bc =
        tf_buffer_.lookupTransform(params_.base_frame, camera_frame, ros::Time(0), ros::Duration(0.5));
    const Eigen::Isometry3d T = tf2::transformToEigen(bc);
    R_base_camera_ = T.rotation();
    t_base_camera_ = T.translation();
    have_base_transform_ = true;
  } catch (const tf2::TransformException& e) {
    have_base_transform_ = false;
    ROS_INFO("hybrid_vo: no %s -> %s transform (%s); publishing %s -> %s", params_.base_frame.c_str(),
             camera_frame.c_str(), e.what(), params_.odom_frame.c_str(), camera_frame.c_str());
  }
}

void VoNode::publish_pose(const ros::Time& stamp, const std::string& camera_frame,
                          const VisualOdometryResult& result, bool lost) {
  if (!looked_up_base_) look_up_base_transform(camera_frame);
  Eigen::Isometry3d camera_in_world = Eigen::Isometry3d::Identity();
  camera_in_world.linear() = result.R_wc;
  camera_in_world.translation() = result.centre;
  Eigen::Isometry3d pose = camera_in_world;
  std::string child = camera_frame;
  if (have_base_transform_) {
    Eigen::Isometry3d base_camera = Eigen::Isometry3d::Identity();
    base_camera.linear() = R_base_camera_;
    base_camera.translation() = t_base_camera_;
    pose = base_camera * camera_in_world * base_camera.inverse();
    child = params_.base_frame;
  }
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = stamp;
  tf.header.frame_id = params_.odom_frame;
  tf.child_frame_id = child;
  tf.transform = to_transform(pose.rotation(), pose.translation());
  if (params_.publish_tf) tf_broadcaster_.sendTransform(tf);
  publish_odometry(tf, pose, result, lost);
}

void VoNode::publish_odometry(const geometry_msgs::TransformStamped& tf,
                              const Eigen::Isometry3d& pose, const VisualOdometryResult& result,
                              bool lost) {
  nav_msgs::Odometry odometry;
  odometry.header = tf.header;
  odometry.child_frame_id = tf.child_frame_id;
  odometry.pose.pose.position.x = pose.translation().x();
  odometry.pose.pose.position.y = pose.translation().y();
  odometry.pose.pose.position.z = pose.translation().z();
  odometry.pose.pose.orientation = tf.transform.rotation;
  // The camera's pose covariance goes where the pose goes: through the static transform into
  // odom -> base_frame. The twist is the pair's mean over its span, in the child frame.
  const Eigen::Matrix3d R_bc =
      have_base_transform_ ? R_base_camera_ : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d t_bc = have_base_transform_ ? t_base_camera_ : Eigen::Vector3d::Zero();
  odometry.pose.covariance = to_covariance(
      have_base_transform_ ? body_pose_covariance(result.pose_covariance, result.R_wc, R_bc, t_bc)
                           : result.pose_covariance);
  PairTwist twist;
  const bool twist_known =
      (result.status == VoStatus::kOk || result.status == VoStatus::kRotationOnly) &&
      pair_twist(result.motion.R, result.motion.t, result.motion_covariance,
                 tf.header.stamp.toSec() - result.reference_stamp, R_bc, t_bc, &twist);
  odometry.twist.twist.linear = to_vector(twist.linear);
  odometry.twist.twist.angular = to_vector(twist.angular);
  odometry.twist.covariance = twist_known && result.motion_covariance_valid
                                  ? to_covariance(twist.covariance)
                                  : unknown_covariance();
  if (lost) odometry.pose.covariance = odometry.twist.covariance = unknown_covariance();
  odometry_pub_.publish(odometry);

  geometry_msgs::PoseStamped p;
  p.header = tf.header;
  p.pose = odometry.pose.pose;
  path_.header = tf.header;
  path_.poses.push_back(p);
  // A bounded window: the latched path is serialised on every frame, so an unbounded one would
  // cost more memory and time with every frame of a long run.
  if (params_.path_max_poses > 0 && path_.poses.size() > static_cast<size_t>(params_.path_max_poses))
    path_.poses.erase(path_.poses.begin(), path_.poses.end() - params_.path_max_poses);
  path_pub_.publish(path_);
}

Eigen::Matrix3d VoNode::R_odom_world() const {
  return have_base_transform_ ? R_base_camera_ : Eigen::Matrix3d::Identity();
}

void VoNode::publish_vanishing_points(const ros::Time& stamp, const VisualOdometryResult& result) {
  // The map's directions, in the odometry frame (the first camera's frame turned into
  // odom_frame), each with its map id and whether this frame's VPs saw it.
  VanishingPoints vps;
  vps.header.stamp = stamp;
  vps.header.frame_id = params_.odom_frame;
  const DirectionMap& map = vo_->direction_map();
  const std::vector<int>& seen = result.orientation.location.direction_id;
  for (const MapDirection& d : map.directions()) {
    VanishingPoint vp;
    vp.id = d.id;
    vp.direction_odom = to_vector(R_odom_world() * d.direction);
    vp.direction_camera = to_vector(result.R_wc.transpose() * d.direction);
    vp.hits = d.hits;
    vp.age = map.frames() - d.created;
    vp.confident = d.confirmed;
    const auto paired = std::find(seen.begin(), seen.end(), d.id);
    vp.seen = paired != seen.end();
    const size_t k = paired - seen.begin();
    std::vector<int> index;
    const std::vector<VpObservation> used =
        vp.seen && k < result.orientation.observations.size()
            ? map.usable({result.orientation.observations[k]}, &index)
            : std::vector<VpObservation>();
    if (!used.empty()) {
      vp.observation_camera = to_vector(used[0].direction);
      for (int i = 0; i < 9; ++i) vp.observation_covariance[i] = used[0].covariance(i / 3, i % 3);
    }
    vp.sigma_deg = d.sigma_deg();
    vp.last_chi2 = d.last_chi2;
    vp.last_gate_passed = d.disagreements == 0;
    vp.gate_failures = d.disagreements;
    vp.total_gate_failures = d.total_disagreements;
    vps.vps.push_back(vp);
  }
  vps_pub_.publish(vps);
}

}  // namespace hybrid_vo
