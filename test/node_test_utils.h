#pragma once

// What the node's rostests share: camera_info and image messages of rendered frames, and a
// harness that publishes the inputs and collects ~relative_pose, tf and /diagnostics.

#include <chrono>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <hybrid_vo/FeatureLines.h>
#include <hybrid_vo/FeaturePoints.h>
#include <hybrid_vo/MotionEstimate.h>
#include <hybrid_vo/VanishingPoints.h>
#include <nav_msgs/Odometry.h>
#include <opencv2/core.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/render/camera_path.h"
#include "hybrid_vo/render/sequence.h"
#include "ros_connections.h"

namespace hybrid_vo {
namespace testing {

// A short rendered corridor at one sample per pixel, for scenarios that need frames, not detail.
inline render::SequenceOptions small_sequence_options(int frames, int width, int height) {
  render::SequenceOptions options;
  options.out_bag = "unused.bag";
  options.frames = frames;
  options.width = width;
  options.height = height;
  options.supersampling = 1;
  return options;
}

inline sensor_msgs::CameraInfo info_of(const PinholeCamera& c, const ros::Time& stamp,
                                const std::string& frame, double tx = 0.0) {
  sensor_msgs::CameraInfo info;
  info.header.stamp = stamp;
  info.header.frame_id = frame;
  info.width = c.width;
  info.height = c.height;
  info.distortion_model = "plumb_bob";
  info.D = {0, 0, 0, 0, 0};
  info.K = {c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {c.fx, 0, c.cx, tx, 0, c.fy, c.cy, 0, 0, 0, 1, 0};
  return info;
}

inline sensor_msgs::Image image_of(const cv::Mat& gray, const ros::Time& stamp, const std::string& frame) {
  sensor_msgs::Image m;
  m.header.stamp = stamp;
  m.header.frame_id = frame;
  m.encoding = sensor_msgs::image_encodings::MONO8;
  m.width = gray.cols;
  m.height = gray.rows;
  m.step = gray.cols;
  m.data.assign(gray.data, gray.data + gray.total());
  return m;
}

// A diagnostic status's value of `key` as a number; -1 when it has none.
inline double diagnostic_value(const diagnostic_msgs::DiagnosticStatus& s, const std::string& key) {
  for (const auto& kv : s.values)
    if (kv.key == key) return std::atof(kv.value.c_str());
  return -1.0;
}

// Publishes frames and waits for the node's answer to each, so that no frame is dropped.
class NodeHarness {
 public:
  NodeHarness() : listener_(buffer_) {
    ros::NodeHandle nh;
    left_ = nh.advertise<sensor_msgs::Image>("camera/left/image_raw", 5);
    left_info_ = nh.advertise<sensor_msgs::CameraInfo>("camera/left/camera_info", 5);
    right_ = nh.advertise<sensor_msgs::Image>("camera/right/image_raw", 5);
    right_info_ = nh.advertise<sensor_msgs::CameraInfo>("camera/right/camera_info", 5);
    points_ = nh.advertise<FeaturePoints>("features/points", 5);
    lines_ = nh.advertise<FeatureLines>("features/lines", 5);
    motion_sub_ = nh.subscribe("hybrid_vo/relative_pose", 100, &NodeHarness::on_motion, this);
    diagnostics_sub_ = nh.subscribe("/diagnostics", 100, &NodeHarness::on_diagnostics, this);
    vps_sub_ = nh.subscribe("hybrid_vo/vanishing_points", 100, &NodeHarness::on_vps, this);
    odometry_sub_ = nh.subscribe("hybrid_vo/odometry", 100, &NodeHarness::on_odometry, this);
  }

  // Waits until the node takes the left camera's topics (and `also`) and the harness hears the
  // node's outputs.
  ::testing::AssertionResult wait_for_node(const std::vector<ros::Publisher>& also = {}) {
    std::vector<std::pair<ros::Publisher, uint32_t>> inputs = {{left_, 1}, {left_info_, 1}};
    for (const ros::Publisher& p : also) inputs.emplace_back(p, 1);
    return wait_connected(inputs, {motion_sub_, diagnostics_sub_, vps_sub_, odometry_sub_});
  }

  // Spins until `done()` or for `seconds` (wall time); whether it was done.
  template <class Done>
  bool spin_until(Done done, double seconds) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::ok() && ros::WallTime::now() < end) {
      ros::spinOnce();
      if (done()) return true;
      ros::WallDuration(0.005).sleep();
    }
    return false;
  }

  // Waits for the ~relative_pose message of `stamp`.
  bool wait_for(const ros::Time& stamp, double seconds = 20.0) {
    return spin_until([&] { return motions_.count(stamp) > 0; }, seconds);
  }

  void spin_for(double seconds) {
    spin_until([] { return false; }, seconds);
  }

  // Spins until the odometry status's `key` reaches at least `value` (diagnostics come about once
  // a second, after the frame that changed them).
  bool wait_for_diagnostic(const std::string& key, double value, double seconds = 5.0) {
    return spin_until([&] { return diagnostic_value(last_odometry_status_, key) >= value; },
                      seconds);
  }

  void on_motion(const MotionEstimate::ConstPtr& m) {
    motions_[m->header.stamp] = *m;
    received_.push_back(*m);
    answer_times_.emplace(m->header.stamp, std::chrono::steady_clock::now());
  }
  void on_diagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& d) {
    for (const auto& s : d->status)
      if (s.name.find("odometry") != std::string::npos) last_odometry_status_ = s;
  }

  ros::Publisher left_, left_info_, right_, right_info_, points_, lines_;
  void on_vps(const VanishingPoints::ConstPtr& v) { last_vps_ = *v; }
  void on_odometry(const nav_msgs::Odometry::ConstPtr& o) { odometry_[o->header.stamp] = *o; }

  ros::Subscriber motion_sub_, diagnostics_sub_, vps_sub_, odometry_sub_;
  std::map<ros::Time, nav_msgs::Odometry> odometry_;  // the last ~odometry per stamp
  VanishingPoints last_vps_;  // the last ~vanishing_points
  std::map<ros::Time, MotionEstimate> motions_;  // the last answer per stamp
  std::vector<MotionEstimate> received_;          // every answer, in arrival order
  // When the first answer per stamp was handled (by spinOnce: spin often to time it well).
  std::map<ros::Time, std::chrono::steady_clock::time_point> answer_times_;
  diagnostic_msgs::DiagnosticStatus last_odometry_status_;
  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener listener_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
};

inline void publish_static_camera(NodeHarness* h) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = "base_link";
  t.child_frame_id = "camera_left_optical";
  const Eigen::Quaterniond q(render::base_from_optical());
  t.transform.rotation.w = q.w();
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  h->static_broadcaster_.sendTransform(t);
}

// nav_msgs/Odometry's covariance arrays as matrices; a lost track's (9999 on the diagonal).
inline Eigen::Matrix<double, 6, 6> covariance_of(const boost::array<double, 36>& a) {
  Eigen::Matrix<double, 6, 6> C;
  for (int i = 0; i < 36; ++i) C(i / 6, i % 6) = a[i];
  return C;
}
inline bool unknown(const boost::array<double, 36>& a) {
  return covariance_of(a) == 9999.0 * Eigen::Matrix<double, 6, 6>::Identity();
}

}  // namespace testing
}  // namespace hybrid_vo
