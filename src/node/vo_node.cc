#include "hybrid_vo/node/vo_node.h"

#include <cmath>
#include <cstdio>

#include <hybrid_vo/MotionEstimate.h>
#include <hybrid_vo/VanishingPoints.h>
#include <nav_msgs/Odometry.h>
#include <opencv2/core/utility.hpp>
#include <visualization_msgs/MarkerArray.h>

#include "hybrid_vo/node/compressed_image.h"
#include "hybrid_vo/node/conversions.h"

namespace hybrid_vo {
namespace {

// For diagnostics: camera_info's model and coefficients, and the pinhole view when the node
// rectified the image into one.
std::string describe_camera(const sensor_msgs::CameraInfo& info, const CameraModel& lens,
                            const CameraModel& used) {
  const std::string model = info.distortion_model.empty() ? "none" : info.distortion_model;
  char text[200];
  if (lens.model != LensModel::kEquidistant) {
    std::snprintf(text, sizeof(text), "%s%s", model.c_str(),
                  lens.has_distortion() ? " (features undistorted)" : " (no distortion)");
  } else if (used.model == LensModel::kEquidistant) {
    std::snprintf(text, sizeof(text),
                  "equidistant k1..k4 = %.4g %.4g %.4g %.4g (features undistorted, not rectified)",
                  lens.distortion[0], lens.distortion[1], lens.distortion[2], lens.distortion[3]);
  } else {
    const PinholeCamera& p = used.pinhole;
    std::snprintf(text, sizeof(text),
                  "equidistant k1..k4 = %.4g %.4g %.4g %.4g, rectified to a pinhole view of "
                  "%.0f deg horizontal (f %.1f px)",
                  lens.distortion[0], lens.distortion[1], lens.distortion[2], lens.distortion[3],
                  2.0 * std::atan(0.5 * p.width / p.fx) * 180.0 / M_PI, p.fx);
  }
  return text;
}

}  // namespace

VoNode::VoNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), pnh_(private_nh), tf_listener_(tf_buffer_), updater_(nh, private_nh) {
  load_parameters();
  vo_ = std::make_unique<VisualOdometry>(params_.odometry);
  queue_ = std::make_unique<FrameQueue<Frame>>(params_.frame_queue_size,
                                               params_.frame_queue_spare);

  relative_pose_pub_ = pnh_.advertise<MotionEstimate>("relative_pose", 10);
  odometry_pub_ = pnh_.advertise<nav_msgs::Odometry>("odometry", 10);
  path_pub_ = pnh_.advertise<nav_msgs::Path>("path", 1, true);
  vps_pub_ = pnh_.advertise<VanishingPoints>("vanishing_points", 10);
  markers_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("markers", 10);
  image_transport::ImageTransport private_it(pnh_);
  debug_image_pub_ = private_it.advertise("debug_image", 1);

  updater_.setHardwareID("hybrid_vo");
  frequency_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&params_.min_frequency, &params_.max_frequency, 0.1, 10));
  updater_.add(*frequency_);
  updater_.add("odometry", this, &VoNode::diagnose);

  subscribe();
  reset_service_ = pnh_.advertiseService("reset", &VoNode::reset_callback, this);
  // diagnostic_updater publishes at the first check after its 1 s period: checking every 0.1 s
  // keeps /diagnostics near 1 Hz (every 0.5 s let gaps of 1.5 s happen).
  watchdog_timer_ = nh_.createTimer(ros::Duration(0.1), &VoNode::watchdog, this);
  worker_ = std::thread(&VoNode::run, this);
  ROS_INFO("hybrid_vo: %s, %s images on %s, %s sync, preset %s, points %s, lines %s%s%s",
           params_.stereo ? "stereo" : "mono", params_.compressed ? "compressed" : "raw", image_topic_.c_str(),
           params_.approximate_sync ? "approximate" : "exact",
           params_.preset.c_str(), params_.points.c_str(),
           params_.odometry.use_lines ? params_.lines.c_str() : "none",
           params_.feature_points ? ", point features from features/points" : "",
           params_.feature_lines ? ", line features from features/lines" : "");
}

VoNode::~VoNode() {
  queue_->close();
  if (worker_.joinable()) worker_.join();
}

void VoNode::load_parameters() {
  XmlRpc::XmlRpcValue values;
  pnh_.getParam(pnh_.getNamespace(), values);  // every private parameter, as a struct
  std::vector<std::string> warnings;
  params_ = read_node_parameters(values, &warnings);
  for (const std::string& warning : warnings) ROS_WARN("hybrid_vo: %s", warning.c_str());
  left_rectifier_ = right_rectifier_ = FisheyeRectifier(params_.rectified_fov_deg);
  monitor_ = StreamMonitor(params_.stream);
  // A pool beside the front end's two threads only contends for the same cores and splits each
  // small search into stripes (on KITTI 10 % more instructions).
  if (params_.opencv_threads >= 0) cv::setNumThreads(params_.opencv_threads);
}

void VoNode::run() {
  Frame frame;
  while (queue_->pop(&frame)) {
    {
      std::lock_guard<std::mutex> lock(process_mutex_);
      process(frame);
    }
    queue_->finished();
    frame = Frame();  // the images are not kept while waiting
  }
}

void VoNode::reset_state(const std::string& why) {
  vo_->reset();
  path_.poses.clear();
  looked_up_base_ = false;
  have_base_transform_ = false;
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
    ROS_WARN("hybrid_vo: %s", what.c_str());
  }
  return true;
}

void VoNode::process(const Frame& frame) {
  // Input checks first, so that a corrupt image's size or stamp never counts as a stream event.
  VisualOdometryInput input;
  if (!read_input(frame, &input)) return;
  bool lost = false;
  if (!handle_stream_event(frame.stamp, input.image.cols, input.image.rows, &lost)) return;

  const VisualOdometryResult result = vo_->process(input);
  monitor_.accept(input.image.cols, input.image.rows);
  record_result(frame, result, lost);
  publish(frame, input, result, lost);
  injected_leak_.on_frame();
  const double latency_ms = std::chrono::duration<double, std::milli>(
                                std::chrono::steady_clock::now() - frame.received)
                                .count();
  std::lock_guard<std::mutex> lock(stats_mutex_);
  latency_ms_.add(latency_ms);
}

bool VoNode::gray_of(const FrameImage& image, const CameraModel& camera, cv::Mat* gray,
                     double* decode_ms, std::string* reason) const {
  if (image.raw) return gray_from_image(image.raw, gray, reason);
  const auto start = std::chrono::steady_clock::now();
  const bool ok = gray_from_compressed(*image.compressed, camera.pinhole.width,
                                       camera.pinhole.height, gray, reason);
  *decode_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count();
  return ok;
}

bool VoNode::rectify(const sensor_msgs::CameraInfo& info, FisheyeRectifier* rectifier,
                     CameraModel* camera, cv::Mat* image, std::string* reason) {
  if (camera->model != LensModel::kEquidistant || !params_.rectify_fisheye) return true;
  Eigen::Matrix3d R;
  if (!rectification_from_info(info, &R)) {
    *reason = "R is not a rotation matrix";
    return false;
  }
  cv::Mat rectified;
  if (!rectifier->rectify(*camera, R, *image, &rectified, camera, reason)) return false;
  *image = rectified;
  return true;
}

bool VoNode::read_input(const Frame& frame, VisualOdometryInput* input) {
  input->stamp = frame.stamp.toSec();
  std::string reason;
  double decode_ms = 0.0;
  if (!camera_from_info(*frame.left_info, &input->camera, &reason))
    return reject("camera_info", reason, &invalid_camera_info_);
  if (!gray_of(frame.left, input->camera, &input->image, &decode_ms, &reason))
    return reject("image", reason, &bad_images_);
  if (input->image.cols != input->camera.pinhole.width ||
      input->image.rows != input->camera.pinhole.height)
    return reject("camera_info", "its size differs from the image's", &invalid_camera_info_);
  const CameraModel lens = input->camera;
  if (!rectify(*frame.left_info, &left_rectifier_, &input->camera, &input->image, &reason))
    return reject("camera_info", reason, &invalid_camera_info_);
  if (params_.stereo) {
    CameraModel right;
    if (!camera_from_info(*frame.right_info, &right, &reason))
      return reject("right camera_info", reason, &invalid_camera_info_);
    if (!gray_of(frame.right, right, &input->right_image, &decode_ms, &reason))
      return reject("right image", reason, &bad_images_);
    if (!rectify(*frame.right_info, &right_rectifier_, &right, &input->right_image, &reason))
      return reject("right camera_info", reason, &invalid_camera_info_);
    if (!baseline_from_info(*frame.right_info, &input->baseline_m))
      return reject("right camera_info", "P has no baseline term (P[3] = -fx * B)",
                    &invalid_camera_info_);
  }
  if (params_.feature_points) {
    const bool ok = params_.vins_format ? points_from_vins(*frame.vins_points, input->camera.pinhole,
                                                    &input->external, &reason)
                                 : points_from_msg(*frame.points, &input->external, &reason);
    if (!ok) return reject("features/points", reason, &bad_features_);
  }
  if (params_.feature_lines) {
    const bool ok = params_.vins_format ? lines_from_vins(*frame.vins_lines, input->camera.pinhole,
                                                   &input->external, &reason)
                                 : lines_from_msg(*frame.lines, &input->external, &reason);
    if (!ok) return reject("features/lines", reason, &bad_features_);
  }
  std::lock_guard<std::mutex> lock(stats_mutex_);
  if (params_.compressed) decode_ms_.add(decode_ms);
  camera_model_ = describe_camera(*frame.left_info, lens, input->camera);
  return true;
}

void VoNode::record_result(const Frame& frame, const VisualOdometryResult& result, bool lost) {
  frequency_->tick();
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++frames_;
    last_processed_ = frame.stamp;
    last_result_ = result;
    if (answered(result.status) || result.status == VoStatus::kLowParallax) {
      // The fault that restarted the chain stays in the summary until a frame pairs again.
      if (!lost) last_problem_.clear();
    } else {
      ++failures_;
      last_problem_ = std::string(to_string(result.status)) + ": " + result.message;
      ROS_WARN_THROTTLE(2.0, "hybrid_vo: %s", last_problem_.c_str());
    }
  }
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    map_directions_ = vo_->direction_map().directions();
    map_structure_ = vo_->direction_map().structure();
    map_stats_ = vo_->direction_map().stats();
    const RelativePoseEstimate& est = result.estimate.estimate;
    for (size_t k = 0; k < est.vp_prior_chi2.size() && k < est.vp_prior_used.size(); ++k) {
      if (est.vp_prior_used[k]) ++vp_priors_used_;
      else if (std::isfinite(est.vp_prior_chi2[k])) ++vp_priors_rejected_;
    }
    rotation_only_frames_ += result.status == VoStatus::kRotationOnly;
    keyframe_before_frames_ += result.paired_with_keyframe_before;
    if (result.status == VoStatus::kOk || result.status == VoStatus::kRotationOnly) {
      blank_wall_frames_ += result.orientation.blank_wall;
      pairs_overruled_ += result.orientation.source == OrientationSource::kPairRejected;
    }
  }
  if (result.stereo_scale_attempted && !result.scale_known) {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++stereo_scale_fallbacks_;
    last_scale_fallback_ = to_string(result.stereo_scale.status);
    ROS_WARN_THROTTLE(5.0, "hybrid_vo: stereo scale: %s (%d near points); mono_scale used",
                      last_scale_fallback_.c_str(), result.stereo_scale.near_points);
  }
}

}  // namespace hybrid_vo
