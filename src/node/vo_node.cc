#include "hybrid_vo/node/vo_node.h"

#include <cmath>

#include <Eigen/Geometry>
#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <hybrid_vo/MotionEstimate.h>
#include <hybrid_vo/VanishingPoints.h>
#include <nav_msgs/Odometry.h>
#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include "hybrid_vo/frontend/visualization.h"
#include "hybrid_vo/node/conversions.h"

namespace hybrid_vo {
namespace {

uint8_t status_code(const VisualOdometryResult& r) {
  switch (r.status) {
    case VoStatus::kOk:
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

geometry_msgs::Vector3 to_vector(const Eigen::Vector3d& v) {
  geometry_msgs::Vector3 m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}

geometry_msgs::Point to_point(const Eigen::Vector3d& v) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}

}  // namespace

VoNode::VoNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), pnh_(private_nh), it_(nh), tf_listener_(tf_buffer_), updater_(nh, private_nh) {
  load_parameters();
  vo_ = std::make_unique<VisualOdometry>(vo_options_);
  queue_ = std::make_unique<FrameQueue<Frame>>(frame_queue_size_);

  relative_pose_pub_ = pnh_.advertise<MotionEstimate>("relative_pose", 10);
  odometry_pub_ = pnh_.advertise<nav_msgs::Odometry>("odometry", 10);
  path_pub_ = pnh_.advertise<nav_msgs::Path>("path", 1, true);
  vps_pub_ = pnh_.advertise<VanishingPoints>("vanishing_points", 10);
  markers_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 10);
  image_transport::ImageTransport private_it(pnh_);
  debug_image_pub_ = private_it.advertise("debug_image", 1);

  updater_.setHardwareID("hybrid_vo");
  frequency_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&min_frequency_, &max_frequency_, 0.1, 10));
  updater_.add(*frequency_);
  updater_.add("odometry", this, &VoNode::diagnose);

  subscribe();
  reset_service_ = pnh_.advertiseService("reset", &VoNode::reset_callback, this);
  watchdog_timer_ = nh_.createTimer(ros::Duration(0.5), &VoNode::watchdog, this);
  worker_ = std::thread(&VoNode::run, this);
  ROS_INFO("hybrid_vo: %s, %s sync, preset %s, points %s, lines %s%s%s",
           stereo_ ? "stereo" : "mono", approximate_sync_ ? "approximate" : "exact",
           pnh_.param<std::string>("preset", "hybrid").c_str(),
           pnh_.param<std::string>("points", "klt").c_str(),
           vo_options_.use_lines ? pnh_.param<std::string>("lines", "fld").c_str() : "none",
           use_feature_points_ ? ", point features from features/points" : "",
           use_feature_lines_ ? ", line features from features/lines" : "");
}

VoNode::~VoNode() {
  queue_->close();
  if (worker_.joinable()) worker_.join();
}

void VoNode::load_parameters() {
  pnh_.param<std::string>("odom_frame", odom_frame_, "odom");
  pnh_.param<std::string>("base_frame", base_frame_, "base_link");
  pnh_.param("stereo", stereo_, false);
  pnh_.param("approximate_sync", approximate_sync_, false);
  pnh_.param("queue_size", queue_size_, 10);
  pnh_.param("publish_tf", publish_tf_, true);
  pnh_.param("feature_points", use_feature_points_, false);
  pnh_.param("feature_lines", use_feature_lines_, false);
  pnh_.param("publish_debug_image", publish_debug_image_, true);
  pnh_.param("publish_markers", publish_markers_, true);
  pnh_.param("camera_info_timeout", camera_info_timeout_, 2.0);
  pnh_.param("min_frequency", min_frequency_, 1.0);
  pnh_.param("max_frequency", max_frequency_, 100.0);
  const std::string format = pnh_.param<std::string>("feature_format", "native");
  vins_format_ = format == "vins";
  if (format != "native" && format != "vins")
    ROS_WARN("hybrid_vo: feature_format '%s' unknown, using 'native'", format.c_str());
  if (queue_size_ < 1) queue_size_ = 1;
  pnh_.param("frame_queue_size", frame_queue_size_, 1);
  if (frame_queue_size_ < 1) {
    ROS_WARN("hybrid_vo: frame_queue_size must be >= 1, using 1");
    frame_queue_size_ = 1;
  }
  pnh_.param("path_max_poses", path_max_poses_, 5000);
  StreamMonitorOptions stream;
  pnh_.param("max_frame_gap", stream.max_gap_s, 1.0);
  if (!(stream.max_gap_s > 0.0)) {
    ROS_WARN("hybrid_vo: max_frame_gap must be > 0 s, using 1");
    stream.max_gap_s = 1.0;
  }
  monitor_ = StreamMonitor(stream);

  VisualOdometryOptions& o = vo_options_;
  const std::string preset = pnh_.param<std::string>("preset", "hybrid");
  if (!preset_options(preset, &o.estimator.estimator)) {
    ROS_WARN("hybrid_vo: unknown preset '%s', using 'hybrid'", preset.c_str());
    preset_options("hybrid", &o.estimator.estimator);
  }
  const std::string points = pnh_.param<std::string>("points", "klt");
  if (points == "sift" || points == "orb") {
    o.point_source = PointFeatureSource::kDescriptors;
    o.features.points.type = points == "orb" ? PointFeatureType::kOrb : PointFeatureType::kSift;
  } else if (points != "klt") {
    ROS_WARN("hybrid_vo: points '%s' unknown, using 'klt'", points.c_str());
  }
  const std::string lines = pnh_.param<std::string>("lines", "fld");
  o.use_lines = lines != "none";
  if (lines == "lsd") o.features.lines.detection.detector = LineDetector::kLsd;
  else if (lines != "fld" && lines != "none")
    ROS_WARN("hybrid_vo: lines '%s' unknown, using 'fld'", lines.c_str());
  o.klt.max_features = pnh_.param("max_features", 1000);
  o.features.points.max_features = o.klt.max_features;
  o.min_parallax_px = pnh_.param("min_parallax_px", 2.0);
  o.mono_scale = pnh_.param("mono_scale", 1.0);
  o.stereo_scale.max_depth_baselines =
      pnh_.param("stereo_max_depth_baselines", o.stereo_scale.max_depth_baselines);
  o.stereo_offset.enabled = pnh_.param("stereo_offset_calibration", o.stereo_offset.enabled);
  o.estimator.estimator.ransac.point_threshold_px = pnh_.param("point_threshold_px", 1.0);
  o.estimator.estimator.ransac.vp_threshold_deg = pnh_.param("vp_threshold_deg", 2.0);
  o.estimator.vp_detection.inlier_threshold_px = pnh_.param("vp_inlier_threshold_px", 2.0);
  // 6, not the pair tools' 15: the video front end's FLD segments are fewer and shorter, and the
  // VP tracker already keeps only VPs that persist (KITTI and demo AUC@10 +1.5 and +1.2 at 6).
  o.estimator.vp_detection.min_inliers = pnh_.param("vp_min_inliers", 6);
  if (o.estimator.vp_detection.min_inliers < 2) {
    ROS_WARN("hybrid_vo: vp_min_inliers must be >= 2 (a VP needs two segments), using 6");
    o.estimator.vp_detection.min_inliers = 6;
  }
  o.use_vp_tracker = pnh_.param("vp_tracker", true);
  o.track_lines = pnh_.param("track_lines", false);
  o.klt.predict_motion = pnh_.param("klt_predict_motion", true);
  o.concurrent = pnh_.param("concurrent_frontend", true);
}

void VoNode::subscribe() {
  const std::string left = stereo_ ? "left/image" : "image";
  const std::string left_info = stereo_ ? "left/camera_info" : "camera_info";
  // TCP_NODELAY: without it Nagle's algorithm holds a small camera_info (or the last segment of
  // an image) until the previous one is acknowledged, which adds up to 40 ms per frame.
  const ros::TransportHints no_delay = ros::TransportHints().tcpNoDelay();
  const image_transport::TransportHints image_hints("raw", no_delay);
  left_sub_.subscribe(it_, left, queue_size_, image_hints);
  left_info_sub_.subscribe(nh_, left_info, queue_size_, no_delay);
  if (stereo_) {
    right_sub_.subscribe(it_, "right/image", queue_size_, image_hints);
    right_info_sub_.subscribe(nh_, "right/camera_info", queue_size_, no_delay);
    if (approximate_sync_) {
      approx_stereo_ = std::make_unique<message_filters::Synchronizer<ApproxStereo>>(
          ApproxStereo(queue_size_), left_sub_, left_info_sub_, right_sub_, right_info_sub_);
      approx_stereo_->registerCallback(&VoNode::stereo_callback, this);
    } else {
      exact_stereo_ = std::make_unique<message_filters::Synchronizer<ExactStereo>>(
          ExactStereo(queue_size_), left_sub_, left_info_sub_, right_sub_, right_info_sub_);
      exact_stereo_->registerCallback(&VoNode::stereo_callback, this);
    }
  } else if (approximate_sync_) {
    approx_mono_ = std::make_unique<message_filters::Synchronizer<ApproxMono>>(
        ApproxMono(queue_size_), left_sub_, left_info_sub_);
    approx_mono_->registerCallback(&VoNode::mono_callback, this);
  } else {
    exact_mono_ = std::make_unique<message_filters::Synchronizer<ExactMono>>(
        ExactMono(queue_size_), left_sub_, left_info_sub_);
    exact_mono_->registerCallback(&VoNode::mono_callback, this);
  }
  // A second, unsynchronised subscription tells "no images" from "images without camera_info".
  raw_image_sub_ = nh_.subscribe(left, 1, &VoNode::raw_image_callback, this, no_delay);
  if (use_feature_points_) {
    points_sub_ = vins_format_ ? nh_.subscribe("features/points", queue_size_,
                                               &VoNode::vins_points_callback, this, no_delay)
                               : nh_.subscribe("features/points", queue_size_,
                                               &VoNode::points_callback, this, no_delay);
  }
  if (use_feature_lines_) {
    lines_sub_ = vins_format_ ? nh_.subscribe("features/lines", queue_size_,
                                              &VoNode::vins_lines_callback, this, no_delay)
                              : nh_.subscribe("features/lines", queue_size_,
                                              &VoNode::lines_callback, this, no_delay);
  }
}

void VoNode::raw_image_callback(const sensor_msgs::ImageConstPtr& image) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_raw_image_ = ros::Time::now();
  ++unsynced_images_;
}

VoNode::Frame& VoNode::pending(const ros::Time& stamp) {
  Frame& f = pending_[stamp];
  f.stamp = stamp;
  // A bounded wait: features or images that never complete a frame are dropped, oldest first.
  while (pending_.size() > 50) {
    pending_.erase(pending_.begin());
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++dropped_;
  }
  return pending_[stamp];
}

void VoNode::mono_callback(const sensor_msgs::ImageConstPtr& image,
                           const sensor_msgs::CameraInfoConstPtr& info) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_synced_image_ = ros::Time::now();
  unsynced_images_ = 0;
  Frame& f = pending(image->header.stamp);
  f.left = image;
  f.left_info = info;
  f.frame_id = image->header.frame_id;
  f.have_images = true;
  try_process(image->header.stamp);
}

void VoNode::stereo_callback(const sensor_msgs::ImageConstPtr& left,
                             const sensor_msgs::CameraInfoConstPtr& left_info,
                             const sensor_msgs::ImageConstPtr& right,
                             const sensor_msgs::CameraInfoConstPtr& right_info) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_synced_image_ = ros::Time::now();
  unsynced_images_ = 0;
  Frame& f = pending(left->header.stamp);
  f.left = left;
  f.left_info = left_info;
  f.right = right;
  f.right_info = right_info;
  f.frame_id = left->header.frame_id;
  f.have_images = true;
  try_process(left->header.stamp);
}

void VoNode::points_callback(const FeaturePoints::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  Frame& f = pending(msg->header.stamp);
  f.points = msg;
  f.have_points = true;
  try_process(msg->header.stamp);
}

void VoNode::lines_callback(const FeatureLines::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  Frame& f = pending(msg->header.stamp);
  f.lines = msg;
  f.have_lines = true;
  try_process(msg->header.stamp);
}

void VoNode::vins_points_callback(const sensor_msgs::PointCloud::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  Frame& f = pending(msg->header.stamp);
  f.vins_points = msg;
  f.have_points = true;
  try_process(msg->header.stamp);
}

void VoNode::vins_lines_callback(const sensor_msgs::PointCloud::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  Frame& f = pending(msg->header.stamp);
  f.vins_lines = msg;
  f.have_lines = true;
  try_process(msg->header.stamp);
}

void VoNode::try_process(const ros::Time& stamp) {
  const auto it = pending_.find(stamp);
  if (it == pending_.end()) return;
  const Frame& f = it->second;
  if (!f.have_images || (use_feature_points_ && !f.have_points) ||
      (use_feature_lines_ && !f.have_lines))
    return;
  Frame frame = f;
  frame.received = std::chrono::steady_clock::now();
  // Everything up to this stamp is either this frame or can no longer be completed in order.
  int incomplete = 0;
  for (auto p = pending_.begin(); p != pending_.end() && p->first <= stamp;) {
    if (p->first < stamp) ++incomplete;
    p = pending_.erase(p);
  }
  if (incomplete > 0) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    dropped_ += incomplete;
  }
  queue_->push(std::move(frame));
}

void VoNode::run() {
  Frame frame;
  while (queue_->pop(&frame)) {
    {
      std::lock_guard<std::mutex> lock(process_mutex_);
      process(frame);
    }
    frame = Frame();  // the images are not kept while waiting
  }
}

void VoNode::reject(const std::string& what, const std::string& reason, int* counter) {
  monitor_.reject();
  std::lock_guard<std::mutex> lock(stats_mutex_);
  ++*counter;
  last_problem_ = what + ": " + reason;
  ROS_WARN_THROTTLE(2.0, "hybrid_vo: skipping frame, %s", last_problem_.c_str());
}

void VoNode::reset_state(const std::string& why) {
  vo_->reset();
  path_.poses.clear();
  looked_up_base_ = false;
  have_base_transform_ = false;
  last_pose_stamp_ = ros::Time();
  ROS_WARN("hybrid_vo: odometry reset (%s)", why.c_str());
}

bool VoNode::reset_callback(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.clear();
  }
  queue_->clear();
  std::lock_guard<std::mutex> lock(process_mutex_);
  monitor_.reset();
  reset_state("reset service");
  return true;
}

bool VoNode::handle_stream_event(const ros::Time& stamp, int width, int height, bool* lost) {
  const StreamEvent event = monitor_.classify(stamp.toSec(), width, height);
  *lost = event == StreamEvent::kBackwards || restarts(event);
  const std::string& what = monitor_.description();
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stream_counters_ = monitor_.counters();
    if (!what.empty()) last_problem_ = what;
  }
  if (skips(event)) {
    ROS_WARN_THROTTLE(2.0, "hybrid_vo: %s", what.c_str());
    return false;
  }
  if (event == StreamEvent::kBackwards) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      pending_.clear();
    }
    reset_state(what);
  } else if (restarts(event)) {
    vo_->restart();
    last_pose_stamp_ = ros::Time();  // no velocity across the fault
    ROS_WARN("hybrid_vo: %s", what.c_str());
  }
  return true;
}

void VoNode::process(const Frame& frame) {
  // Input checks first, so that a corrupt image's size or stamp never counts as a stream event.
  VisualOdometryInput input;
  input.stamp = frame.stamp.toSec();
  std::string reason;
  if (!camera_from_info(*frame.left_info, &input.camera, &reason))
    return reject("camera_info", reason, &invalid_camera_info_);
  if (!gray_from_image(frame.left, &input.image, &reason))
    return reject("image", reason, &bad_images_);
  if (static_cast<int>(frame.left->width) != input.camera.pinhole.width ||
      static_cast<int>(frame.left->height) != input.camera.pinhole.height)
    return reject("camera_info", "its size differs from the image's", &invalid_camera_info_);
  if (stereo_) {
    CameraModel right;
    if (!camera_from_info(*frame.right_info, &right, &reason))
      return reject("right camera_info", reason, &invalid_camera_info_);
    if (!gray_from_image(frame.right, &input.right_image, &reason))
      return reject("right image", reason, &bad_images_);
    if (!baseline_from_info(*frame.right_info, &input.baseline_m))
      return reject("right camera_info", "P has no baseline term (P[3] = -fx * B)",
                    &invalid_camera_info_);
  }
  if (use_feature_points_) {
    const bool ok = vins_format_ ? points_from_vins(*frame.vins_points, input.camera.pinhole,
                                                    &input.external, &reason)
                                 : points_from_msg(*frame.points, &input.external, &reason);
    if (!ok) return reject("features/points", reason, &bad_features_);
  }
  if (use_feature_lines_) {
    const bool ok = vins_format_ ? lines_from_vins(*frame.vins_lines, input.camera.pinhole,
                                                   &input.external, &reason)
                                 : lines_from_msg(*frame.lines, &input.external, &reason);
    if (!ok) return reject("features/lines", reason, &bad_features_);
  }
  bool lost = false;
  if (!handle_stream_event(frame.stamp, input.image.cols, input.image.rows, &lost)) return;

  const VisualOdometryResult result = vo_->process(input);
  monitor_.accept(input.image.cols, input.image.rows);
  frequency_->tick();
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++frames_;
    last_processed_ = frame.stamp;
    last_result_ = result;
    if (result.status == VoStatus::kOk || result.status == VoStatus::kFirstFrame ||
        result.status == VoStatus::kLowParallax) {
      // The fault that restarted the chain stays in the summary until a frame pairs again.
      if (!lost) last_problem_.clear();
    } else {
      ++failures_;
      last_problem_ = std::string(to_string(result.status)) + ": " + result.message;
      ROS_WARN_THROTTLE(2.0, "hybrid_vo: %s", last_problem_.c_str());
    }
  }
  if (result.stereo_scale_attempted && !result.scale_known) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stereo_scale_fallbacks_;
    last_scale_fallback_ = to_string(result.stereo_scale.status);
    ROS_WARN_THROTTLE(5.0, "hybrid_vo: stereo scale: %s (%d near points); mono_scale used",
                      last_scale_fallback_.c_str(), result.stereo_scale.near_points);
  }
  publish(frame, input, result, lost);
  const double latency_ms = std::chrono::duration<double, std::milli>(
                                std::chrono::steady_clock::now() - frame.received)
                                .count();
  std::lock_guard<std::mutex> lock(stats_mutex_);
  latency_ms_.add(latency_ms);
}

void VoNode::publish(const Frame& frame, const VisualOdometryInput& input,
                     const VisualOdometryResult& result, bool lost) {
  camera_frame_ = frame.frame_id;
  const RelativePoseEstimate& est = result.estimate.estimate;

  MotionEstimate rel;
  rel.header.stamp = frame.stamp;
  rel.header.frame_id = frame.frame_id;
  rel.reference_stamp = ros::Time(result.reference_stamp);
  rel.reference_frame_id = frame.frame_id;
  rel.status = status_code(result);
  const std::string& message = lost ? monitor_.description() : result.message;
  rel.status_text =
      std::string(to_string(result.status)) + (message.empty() ? "" : ": " + message);
  const bool moved = result.status == VoStatus::kOk;
  rel.transform = moved ? to_transform(result.motion.R, result.motion.t)
                        : to_transform(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  rel.scale_known = moved && result.scale_known;
  if (moved && result.motion_covariance_valid) {
    // The estimator's covariance for the translation as published, with a stereo scale's
    // uncertainty along t.
    for (int i = 0; i < 36; ++i) rel.covariance[i] = result.motion_covariance(i / 6, i % 6);
  }
  rel.points = result.num_point_matches;
  rel.lines = result.num_line_matches;
  rel.point_inliers = est.num_point_inliers;
  rel.line_inliers = est.num_line_inliers;
  rel.junctions = est.junctions.size();
  rel.junction_inliers = est.num_junction_inliers;
  rel.vps = result.matches.vps.size();
  rel.vp_inliers = est.num_vp_inliers;
  for (const SolverInfo& info : solver_table()) {
    const SolverStatistics& s = est.solvers[static_cast<int>(info.id)];
    if (s.sampled == 0) continue;
    rel.solvers.push_back(info.code);
    rel.solver_sampled.push_back(s.sampled);
    rel.solver_best.push_back(s.best);
  }
  if (moved) rel.best_solver = solver_info(est.best_solver).code;
  rel.iterations = est.iterations;
  rel.frontend_ms = result.frontend_ms;
  rel.estimator_ms = result.estimator_ms;
  rel.total_ms = result.total_ms;
  rel.points_ms = result.stages.points_ms;
  rel.redetect_ms = result.stages.redetect_ms;
  rel.lines_ms = result.stages.lines_ms;
  rel.line_matching_ms = result.stages.line_matching_ms;
  rel.vps_ms = result.stages.vps_ms;
  rel.ransac_ms = result.stages.ransac_ms;
  rel.stereo_ms = result.stages.stereo_ms;
  relative_pose_pub_.publish(rel);

  if (moved || result.status == VoStatus::kFirstFrame || result.status == VoStatus::kReset)
    publish_pose(frame.stamp, frame.frame_id, result, lost);

  // Tracked VPs, in the odometry frame (the first camera's frame turned into odom_frame).
  const Eigen::Matrix3d R_odom_world = have_base_transform_ ? R_base_camera_
                                                             : Eigen::Matrix3d::Identity();
  VanishingPoints vps;
  vps.header.stamp = frame.stamp;
  vps.header.frame_id = odom_frame_;
  for (const VpTrack& track : vo_->vp_tracker().tracks()) {
    VanishingPoint vp;
    vp.id = track.id;
    vp.direction_odom = to_vector(R_odom_world * track.direction);
    vp.direction_camera = to_vector(result.R_wc.transpose() * track.direction);
    vp.hits = track.hits;
    vp.age = track.age;
    vp.confident = track.confident;
    vps.vps.push_back(vp);
  }
  vps_pub_.publish(vps);

  if (publish_markers_ && markers_pub_.getNumSubscribers() > 0) {
    visualization_msgs::MarkerArray markers;
    visualization_msgs::Marker clear;
    clear.action = visualization_msgs::Marker::DELETEALL;
    markers.markers.push_back(clear);
    const Eigen::Vector3d centre = R_odom_world * result.centre +
                                   (have_base_transform_ ? t_base_camera_ : Eigen::Vector3d::Zero());
    for (const VpTrack& track : vo_->vp_tracker().tracks()) {
      if (!track.confident) continue;
      visualization_msgs::Marker arrow;
      arrow.header = vps.header;
      arrow.ns = "vanishing_points";
      arrow.id = track.id;
      arrow.type = visualization_msgs::Marker::ARROW;
      arrow.scale.x = 0.05;
      arrow.scale.y = 0.1;
      arrow.scale.z = 0.1;
      const cv::Scalar c = vp_colour(track.id);
      arrow.color.b = c[0] / 255.0;
      arrow.color.g = c[1] / 255.0;
      arrow.color.r = c[2] / 255.0;
      arrow.color.a = 1.0;
      arrow.pose.orientation.w = 1.0;
      arrow.points = {to_point(centre), to_point(centre + R_odom_world * track.direction)};
      markers.markers.push_back(arrow);
    }
    // Inlier segments in 3D, where the depth is known: each current endpoint back-projected onto
    // the plane of the matched keyframe segment (metric only with a known scale).
    if (moved && result.scale_known) {
      visualization_msgs::Marker lines;
      lines.header = vps.header;
      lines.ns = "inlier_segments";
      lines.type = visualization_msgs::Marker::LINE_LIST;
      lines.scale.x = 0.02;
      lines.color.r = lines.color.g = 0.9;
      lines.color.b = 0.2;
      lines.color.a = 1.0;
      lines.pose.orientation.w = 1.0;
      const Eigen::Matrix3d& R = result.motion.R;
      const Eigen::Vector3d& t = result.motion.t;
      const PinholeCamera& cam = input.camera.pinhole;
      for (size_t i = 0; i < result.matches.lines.size() && i < est.line_inliers.size(); ++i) {
        if (!est.line_inliers[i]) continue;
        const LineMatch& m = result.matches.lines[i];
        const Eigen::Vector3d l1 = LineSegment(cam.normalize(m.s1.p1), cam.normalize(m.s1.p2)).line();
        const Eigen::Vector3d n = R * l1;
        Eigen::Vector3d ends[2];
        bool ok = true;
        for (int e = 0; e < 2 && ok; ++e) {
          const Eigen::Vector3d b = homogeneous(cam.normalize(e == 0 ? m.s2.p1 : m.s2.p2));
          const double mu = n.dot(t) / n.dot(b);
          ok = std::isfinite(mu) && mu > 0.2 && mu < 100.0;
          ends[e] = R_odom_world * (result.R_wc * (mu * b) + result.centre) +
                    (have_base_transform_ ? t_base_camera_ : Eigen::Vector3d::Zero());
        }
        if (!ok) continue;
        lines.points.push_back(to_point(ends[0]));
        lines.points.push_back(to_point(ends[1]));
      }
      if (!lines.points.empty()) markers.markers.push_back(lines);
    }
    markers_pub_.publish(markers);
  }

  if (publish_debug_image_ && debug_image_pub_.getNumSubscribers() > 0) {
    std::vector<Eigen::Vector2d> points;
    for (size_t i = 0; i < result.matches.points.size() && i < est.point_inliers.size(); ++i)
      if (est.point_inliers[i]) points.push_back(result.matches.points[i].x2);
    std::vector<LineSegment> segments;
    std::vector<int> labels;
    for (size_t i = 0; i < result.matches.lines.size() && i < est.line_inliers.size(); ++i) {
      if (!est.line_inliers[i]) continue;
      segments.push_back(result.matches.lines[i].s2);
      labels.push_back(i < result.matches.line_vp.size() ? result.matches.line_vp[i] : -1);
    }
    std::vector<Eigen::Vector3d> directions;
    for (const VpMatch& v : result.matches.vps) directions.push_back(v.d2);
    const cv::Mat canvas =
        draw_view(input.image, points, segments, labels, directions, input.camera.pinhole);
    debug_image_pub_.publish(cv_bridge::CvImage(frame.left->header, "bgr8", canvas).toImageMsg());
  }
}

void VoNode::publish_pose(const ros::Time& stamp, const std::string& camera_frame,
                          const VisualOdometryResult& result, bool lost) {
  if (!looked_up_base_) {
    // The body frame sits at the camera through a (static) transform; odom starts at the body.
    looked_up_base_ = true;
    try {
      const geometry_msgs::TransformStamped bc =
          tf_buffer_.lookupTransform(base_frame_, camera_frame, ros::Time(0), ros::Duration(0.5));
      const Eigen::Isometry3d T = tf2::transformToEigen(bc);
      R_base_camera_ = T.rotation();
      t_base_camera_ = T.translation();
      have_base_transform_ = true;
    } catch (const tf2::TransformException& e) {
      have_base_transform_ = false;
      ROS_INFO("hybrid_vo: no %s -> %s transform (%s); publishing %s -> %s", base_frame_.c_str(),
               camera_frame.c_str(), e.what(), odom_frame_.c_str(), camera_frame.c_str());
    }
  }
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
    child = base_frame_;
  }
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = stamp;
  tf.header.frame_id = odom_frame_;
  tf.child_frame_id = child;
  tf.transform = to_transform(pose.rotation(), pose.translation());
  if (publish_tf_) tf_broadcaster_.sendTransform(tf);

  nav_msgs::Odometry odometry;
  odometry.header = tf.header;
  odometry.child_frame_id = child;
  odometry.pose.pose.position.x = pose.translation().x();
  odometry.pose.pose.position.y = pose.translation().y();
  odometry.pose.pose.position.z = pose.translation().z();
  odometry.pose.pose.orientation = tf.transform.rotation;
  if (lost) {
    for (int i = 0; i < 6; ++i) {
      odometry.pose.covariance[i * 7] = 9999.0;
      odometry.twist.covariance[i * 7] = 9999.0;
    }
  }
  if (!last_pose_stamp_.isZero() && stamp > last_pose_stamp_) {
    const double dt = (stamp - last_pose_stamp_).toSec();
    const Eigen::Vector3d velocity =
        pose.rotation().transpose() * (pose.translation() - last_centre_) / dt;
    odometry.twist.twist.linear = to_vector(velocity);
  }
  last_pose_stamp_ = stamp;
  last_centre_ = pose.translation();
  odometry_pub_.publish(odometry);

  geometry_msgs::PoseStamped p;
  p.header = tf.header;
  p.pose = odometry.pose.pose;
  path_.header = tf.header;
  path_.poses.push_back(p);
  // A bounded window: the latched path is serialised on every frame, so an unbounded one would
  // cost more memory and time with every frame of a long run.
  if (path_max_poses_ > 0 && path_.poses.size() > static_cast<size_t>(path_max_poses_))
    path_.poses.erase(path_.poses.begin(), path_.poses.end() - path_max_poses_);
  path_pub_.publish(path_);
}

void VoNode::watchdog(const ros::TimerEvent&) {
  const ros::Time now = ros::Time::now();
  bool images_flow = false, frames_flow = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    images_flow =
        !last_raw_image_.isZero() && (now - last_raw_image_).toSec() < camera_info_timeout_;
    // A few images in a row, not one that is waiting for its camera_info after a pause.
    frames_flow = unsynced_images_ < 3 || (!last_synced_image_.isZero() &&
                                           (now - last_synced_image_).toSec() < camera_info_timeout_);
  }
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    if (images_flow && !frames_flow) {
      last_problem_ = "images arrive without a matching camera_info" +
                      std::string(stereo_ ? " (or without their stereo partner)" : "");
      // One outage, however long; the frame after it restarts the chain (a time gap).
      if (!camera_info_outage_) ++camera_info_outages_;
      camera_info_outage_ = true;
      ROS_WARN_THROTTLE(5.0, "hybrid_vo: %s", last_problem_.c_str());
    } else if (frames_flow) {
      camera_info_outage_ = false;
    }
  }
  updater_.update();
}

void VoNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  std::lock_guard<std::mutex> lock(stats_mutex_);
  const VisualOdometryResult& r = last_result_;
  unsigned char level = DiagnosticStatus::OK;
  std::string summary = frames_ == 0 ? "waiting for images" : "tracking";
  if (frames_ == 0) level = DiagnosticStatus::WARN;
  if (frames_ > 0) {
    summary = std::string("last frame: ") + to_string(r.status);
    if (r.status == VoStatus::kNoPose || r.status == VoStatus::kTooFewFeatures ||
        r.status == VoStatus::kReset)
      level = DiagnosticStatus::WARN;
    if (r.status == VoStatus::kInvalidInput) level = DiagnosticStatus::ERROR;
  }
  if (!last_problem_.empty()) {
    level = std::max<unsigned char>(level, last_problem_.rfind("images arrive", 0) == 0 ||
                                                   last_problem_.rfind("camera_info", 0) == 0 ||
                                                   last_problem_.rfind("image", 0) == 0
                                               ? DiagnosticStatus::ERROR
                                               : DiagnosticStatus::WARN);
    summary = last_problem_;
  }
  status.summary(level, summary);
  const RelativePoseEstimate& est = r.estimate.estimate;
  status.add("frames processed", frames_);
  status.add("last stamp", last_processed_.toSec());
  status.add("delay (s)", last_processed_.isZero() ? 0.0 : (ros::Time::now() - last_processed_).toSec());
  status.add("tracking state", to_string(r.status));
  status.add("point matches", r.num_point_matches);
  status.add("point inliers", est.num_point_inliers);
  status.add("line matches", r.num_line_matches);
  status.add("line inliers", est.num_line_inliers);
  status.add("VP inliers", est.num_vp_inliers);
  status.add("scale known", r.scale_known);
  if (r.stereo_scale_attempted) {
    status.add("stereo scale", to_string(r.stereo_scale.status));
    status.add("stereo scale sigma (m)", r.stereo_scale.sigma);
    status.add("stereo near points", r.stereo_scale.near_points);
    status.add("disparity offset (px)", r.disparity_offset_px);
  }
  status.add("stereo scale fallbacks", stereo_scale_fallbacks_);
  if (!last_scale_fallback_.empty()) status.add("last stereo scale fallback", last_scale_fallback_);
  status.add("front end (ms)", r.frontend_ms);
  status.add("estimator (ms)", r.estimator_ms);
  status.add("total (ms)", r.total_ms);
  status.add("points (ms)", r.stages.points_ms);
  status.add("re-detection (ms)", r.stages.redetect_ms);
  status.add("lines (ms)", r.stages.lines_ms);
  status.add("line matching (ms)", r.stages.line_matching_ms);
  status.add("VPs (ms)", r.stages.vps_ms);
  status.add("RANSAC (ms)", r.stages.ransac_ms);
  status.add("stereo (ms)", r.stages.stereo_ms);
  status.add("segments tracked", r.line_tracking.tracked);
  status.add("segments matched by descriptor", r.line_tracking.fallback);
  status.add("invalid camera_info", invalid_camera_info_);
  status.add("bad images", bad_images_);
  status.add("bad feature messages", bad_features_);
  status.add("frames without pose", failures_);
  status.add("incomplete frames dropped", dropped_);
  // Load: frames dropped because the processing thread was busy, and the time from a frame's
  // arrival to its publication over the last 200 frames.
  status.add("frames dropped (queue full)", queue_->dropped());
  status.add("queue length", queue_->size());
  status.add("latency p50 (ms)", latency_ms_.quantile(0.5));
  status.add("latency p99 (ms)", latency_ms_.quantile(0.99));
  // Faults in the stream (stream_monitor.h).
  status.add("time jumps (resets)", stream_counters_.backwards);
  status.add("time gaps (restarts)", stream_counters_.gaps);
  status.add("image size changes (restarts)", stream_counters_.size_changes);
  status.add("restarts after rejected input", stream_counters_.after_faults);
  status.add("duplicate stamps skipped", stream_counters_.duplicates);
  status.add("late frames skipped", stream_counters_.late);
  status.add("camera_info outages", camera_info_outages_);
}

}  // namespace hybrid_vo
