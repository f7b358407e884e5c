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
  ROS_INFO("hybrid_vo: %s, %s images on %s, %s sync, preset %s, points %s, lines %s%s%s",
           stereo_ ? "stereo" : "mono", compressed_ ? "compressed" : "raw", image_topic_.c_str(),
           approximate_sync_ ? "approximate" : "exact",
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
  pnh_.param("rectify_fisheye", rectify_fisheye_, true);
  double fov_deg = pnh_.param("rectified_fov_deg", 100.0);
  if (!(fov_deg >= 10.0 && fov_deg <= 170.0)) {
    ROS_WARN("hybrid_vo: rectified_fov_deg must be in [10, 170], using 100");
    fov_deg = 100.0;
  }
  left_rectifier_ = right_rectifier_ = FisheyeRectifier(fov_deg);
  // As the standard image_transport parameter, but decoded here: Debian has no plugin for it.
  const std::string transport = pnh_.param<std::string>("image_transport", "raw");
  compressed_ = transport == "compressed";
  if (transport != "raw" && transport != "compressed")
    ROS_WARN("hybrid_vo: image_transport '%s' unknown (raw or compressed), using 'raw'",
             transport.c_str());
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
  load_odometry_options();
}

void VoNode::load_odometry_options() {
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
  o.stereo_refine_tracks = pnh_.param("stereo_refine_tracks", o.stereo_refine_tracks);
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
  o.track_lines = pnh_.param("track_lines", o.track_lines);
  o.anchor_orientation = pnh_.param("anchor_orientation", o.anchor_orientation);
  o.klt.min_corner_gradient = pnh_.param("klt_min_corner_gradient", o.klt.min_corner_gradient);
  o.klt.predict_motion = pnh_.param("klt_predict_motion", true);
  o.klt.window_px = pnh_.param("klt_window_px", o.klt.window_px);
  if (o.klt.window_px < 5) {
    ROS_WARN("hybrid_vo: klt_window_px must be >= 5, using %d", KltTrackerOptions().window_px);
    o.klt.window_px = KltTrackerOptions().window_px;
  }
  o.concurrent = pnh_.param("concurrent_frontend", true);
  // OpenCV's own thread pool, for the whole process: the front end splits its work over its two
  // threads itself (issue 32), and a pool beside them only contends for the same cores and
  // splits each small search into stripes (on KITTI 10 % more instructions). < 0: OpenCV's
  // default.
  const int opencv_threads = pnh_.param("opencv_threads", 1);
  if (opencv_threads >= 0) cv::setNumThreads(opencv_threads);
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
  if (!read_input(frame, &input)) return;
  bool lost = false;
  if (!handle_stream_event(frame.stamp, input.image.cols, input.image.rows, &lost)) return;

  const VisualOdometryResult result = vo_->process(input);
  monitor_.accept(input.image.cols, input.image.rows);
  record_result(frame, result, lost);
  publish(frame, input, result, lost);
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
  if (camera->model != LensModel::kEquidistant || !rectify_fisheye_) return true;
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
  if (stereo_) {
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
  if (use_feature_points_) {
    const bool ok = vins_format_ ? points_from_vins(*frame.vins_points, input->camera.pinhole,
                                                    &input->external, &reason)
                                 : points_from_msg(*frame.points, &input->external, &reason);
    if (!ok) return reject("features/points", reason, &bad_features_);
  }
  if (use_feature_lines_) {
    const bool ok = vins_format_ ? lines_from_vins(*frame.vins_lines, input->camera.pinhole,
                                                   &input->external, &reason)
                                 : lines_from_msg(*frame.lines, &input->external, &reason);
    if (!ok) return reject("features/lines", reason, &bad_features_);
  }
  std::lock_guard<std::mutex> lock(stats_mutex_);
  if (compressed_) decode_ms_.add(decode_ms);
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
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    vp_tracks_ = vo_->vp_tracker().tracks();
    const RelativePoseEstimate& est = result.estimate.estimate;
    for (size_t k = 0; k < est.vp_prior_chi2.size() && k < est.vp_prior_used.size(); ++k) {
      if (est.vp_prior_used[k]) ++vp_priors_used_;
      else if (std::isfinite(est.vp_prior_chi2[k])) ++vp_priors_rejected_;
    }
    for (const VpAssociation& a : result.vp_associations) vp_track_gate_failures_ += a.gated_out;
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
