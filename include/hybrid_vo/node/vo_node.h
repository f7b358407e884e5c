#pragma once

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <Eigen/Geometry>
#include <geometry_msgs/TransformStamped.h>
#include <hybrid_vo/FeatureLines.h>
#include <hybrid_vo/FeaturePoints.h>
#include <image_transport/image_transport.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/Marker.h>

#include "hybrid_vo/features/fisheye_rectifier.h"
#include "hybrid_vo/node/frame_queue.h"
#include "hybrid_vo/node/injected_leak.h"
#include "hybrid_vo/node/latency_window.h"
#include "hybrid_vo/node/node_parameters.h"
#include "hybrid_vo/node/stream_monitor.h"
#include "hybrid_vo/odometry/visual_odometry.h"

namespace hybrid_vo {

// The ROS wrapper around VisualOdometry: synchronised image (+ camera_info) input, mono or stereo,
// optional feature topics, and the outputs of DESIGN.md "The node". Usable from a node's main()
// or from the nodelet. Callbacks only assemble frames and hand them to a processing thread
// through a bounded queue (frame_queue.h), so that a slow frame never backs up the subscribers.
class VoNode {
 public:
  VoNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  ~VoNode();

 private:
  // An image as it arrived: raw, or compressed (image_transport: compressed), which the
  // processing thread decodes.
  struct FrameImage {
    FrameImage() = default;
    explicit FrameImage(sensor_msgs::ImageConstPtr image) : raw(std::move(image)) {}
    explicit FrameImage(sensor_msgs::CompressedImageConstPtr image)
        : compressed(std::move(image)) {}
    sensor_msgs::ImageConstPtr raw;
    sensor_msgs::CompressedImageConstPtr compressed;
  };
  struct Frame {
    ros::Time stamp;
    std::chrono::steady_clock::time_point received;  // when it was complete
    std::string frame_id;
    FrameImage left, right;  // right empty for mono
    sensor_msgs::CameraInfoConstPtr left_info, right_info;
    bool have_images = false, have_points = false, have_lines = false;
    FeaturePoints::ConstPtr points;
    FeatureLines::ConstPtr lines;
    sensor_msgs::PointCloud::ConstPtr vins_points, vins_lines;
  };

  // Parameters and processing (vo_node.cc).
  void load_parameters();
  // The processing thread: frames from the queue, one at a time, in arrival order.
  void run();
  void process(const Frame& frame);
  // The frame's cameras, images and features for the odometry; false when one is unusable (the
  // frame is rejected and counted).
  bool read_input(const Frame& frame, VisualOdometryInput* input);
  // An image in 8-bit grey; a compressed one is decoded, refused unless it has the camera's size,
  // and its decoding time added to *decode_ms.
  bool gray_of(const FrameImage& image, const CameraModel& camera, cv::Mat* gray,
               double* decode_ms, std::string* reason) const;
  // An equidistant camera's image rectified into the pinhole view (rectify_fisheye), its camera
  // replaced by the view's; other cameras and images are left as they are.
  bool rectify(const sensor_msgs::CameraInfo& info, FisheyeRectifier* rectifier,
               CameraModel* camera, cv::Mat* image, std::string* reason);
  // The frame's outcome for the diagnostics.
  void record_result(const Frame& frame, const VisualOdometryResult& result, bool lost);
  // Resets or restarts the odometry for a fault in the stream (a valid frame of this stamp and
  // size); false to skip the frame.
  bool handle_stream_event(const ros::Time& stamp, int width, int height, bool* lost);
  bool reset_callback(std_srvs::Empty::Request&, std_srvs::Empty::Response&);
  void reset_state(const std::string& why);

  // Inputs and synchronisation (vo_node_inputs.cc). ImageMsg is sensor_msgs::Image or
  // sensor_msgs::CompressedImage (image_transport: compressed, on <image topic>/compressed).
  void subscribe();
  template <class ImageMsg>
  void synchronise(message_filters::Subscriber<ImageMsg>* left,
                   message_filters::Subscriber<ImageMsg>* right);
  template <class ImageMsg>
  void mono_callback(const boost::shared_ptr<const ImageMsg>& image,
                     const sensor_msgs::CameraInfoConstPtr& info);
  template <class ImageMsg>
  void stereo_callback(const boost::shared_ptr<const ImageMsg>& left,
                       const sensor_msgs::CameraInfoConstPtr& left_info,
                       const boost::shared_ptr<const ImageMsg>& right,
                       const sensor_msgs::CameraInfoConstPtr& right_info);
  // A frame whose parts never all arrived (an image or a camera_info lost in transport): the
  // exact synchroniser gives it up once a later frame completes, and it is counted.
  template <class ImageMsg>
  void mono_dropped(const boost::shared_ptr<const ImageMsg>&, const sensor_msgs::CameraInfoConstPtr&);
  template <class ImageMsg>
  void stereo_dropped(const boost::shared_ptr<const ImageMsg>&, const sensor_msgs::CameraInfoConstPtr&,
                      const boost::shared_ptr<const ImageMsg>&, const sensor_msgs::CameraInfoConstPtr&);
  // Frames that can no longer be completed, into "incomplete frames dropped".
  void count_incomplete(int frames);
  // Every image of the (left) topic, synchronised or not: tells "no images" from "images
  // without camera_info".
  template <class ImageMsg>
  void image_arrived(const boost::shared_ptr<const ImageMsg>& image);
  void points_callback(const FeaturePoints::ConstPtr& msg);
  void lines_callback(const FeatureLines::ConstPtr& msg);
  void vins_points_callback(const sensor_msgs::PointCloud::ConstPtr& msg);
  void vins_lines_callback(const sensor_msgs::PointCloud::ConstPtr& msg);
  // The synchronised images of a frame (right and right_info empty for mono).
  void add_images(const std_msgs::Header& header, const FrameImage& left,
                  const sensor_msgs::CameraInfoConstPtr& left_info, const FrameImage& right,
                  const sensor_msgs::CameraInfoConstPtr& right_info);
  template <class MessagePtr>
  void add_features(const MessagePtr& msg, MessagePtr Frame::*part, bool Frame::*have);
  // Frames wait here until every part (images, and the feature topics in use) has arrived.
  Frame& pending(const ros::Time& stamp);
  void try_process(const ros::Time& stamp);

  // Publishing of the motion, pose, tf, Odometry, path and VPs (vo_node_publishing.cc).
  void publish(const Frame& frame, const VisualOdometryInput& input,
               const VisualOdometryResult& result, bool lost);
  void publish_relative_pose(const Frame& frame, const VisualOdometryResult& result, bool lost);
  // `lost`: the pose follows a fault in the stream, so its covariance says "unknown" (9999, as
  // viso2 reports a lost track).
  void publish_pose(const ros::Time& stamp, const std::string& camera_frame,
                    const VisualOdometryResult& result, bool lost);
  void look_up_base_transform(const std::string& camera_frame);
  // The pose with its covariance (mapped like the pose) and the pair's twist in the child frame;
  // lost, or without a pair (first frame): the twist's covariance says "unknown".
  void publish_odometry(const geometry_msgs::TransformStamped& tf, const Eigen::Isometry3d& pose,
                        const VisualOdometryResult& result, bool lost);
  void publish_vanishing_points(const ros::Time& stamp, const VisualOdometryResult& result);
  // The odometry frame's orientation in the first camera's frame ("world"): the static base ->
  // camera rotation when there is one.
  Eigen::Matrix3d R_odom_world() const;

  // Visualisation, only with subscribers (vo_node_visualisation.cc).
  void publish_markers(const ros::Time& stamp, const VisualOdometryInput& input,
                       const VisualOdometryResult& result);
  visualization_msgs::Marker inlier_segments(const VisualOdometryInput& input,
                                             const VisualOdometryResult& result) const;
  void publish_debug_image(const Frame& frame, const VisualOdometryInput& input,
                           const VisualOdometryResult& result);

  // Diagnostics (vo_node_diagnostics.cc). reject counts a skipped frame and returns false.
  bool reject(const std::string& what, const std::string& reason, int* counter);
  void watchdog(const ros::TimerEvent&);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  // Under stats_mutex_.
  void add_tracking(diagnostic_updater::DiagnosticStatusWrapper& status) const;
  void add_counters(diagnostic_updater::DiagnosticStatusWrapper& status) const;
  void add_input(diagnostic_updater::DiagnosticStatusWrapper& status) const;
  void add_vp_tracks(diagnostic_updater::DiagnosticStatusWrapper& status) const;

  ros::NodeHandle nh_, pnh_;

  NodeParameters params_;

  // Input: one pair of image subscribers is in use (raw or compressed), and one synchroniser
  // (mono or stereo, exact or approximate time, of those images), held type-erased.
  message_filters::Subscriber<sensor_msgs::Image> left_sub_, right_sub_;
  message_filters::Subscriber<sensor_msgs::CompressedImage> left_compressed_sub_,
      right_compressed_sub_;
  message_filters::Subscriber<sensor_msgs::CameraInfo> left_info_sub_, right_info_sub_;
  std::shared_ptr<void> sync_;
  std::string image_topic_;  // the (left) image topic subscribed, for diagnostics
  ros::Subscriber arrival_sub_, points_sub_, lines_sub_;
  ros::ServiceServer reset_service_;
  ros::Timer watchdog_timer_;

  // Output.
  ros::Publisher relative_pose_pub_, odometry_pub_, path_pub_, vps_pub_, markers_pub_;
  image_transport::Publisher debug_image_pub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  nav_msgs::Path path_;

  // Input side (callbacks): partial frames and arrival times, under mutex_.
  std::mutex mutex_;
  std::map<ros::Time, Frame> pending_;
  std::unique_ptr<FrameQueue<Frame>> queue_;
  std::thread worker_;

  // Processing side: only the processing thread (or the reset service, under process_mutex_)
  // touches the odometry and the publishers' state.
  std::mutex process_mutex_;
  std::unique_ptr<VisualOdometry> vo_;
  // Per camera: the remap tables of the last equidistant camera_info.
  FisheyeRectifier left_rectifier_, right_rectifier_;
  StreamMonitor monitor_;
  bool have_base_transform_ = false, looked_up_base_ = false;
  Eigen::Matrix3d R_base_camera_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_base_camera_ = Eigen::Vector3d::Zero();
  std::string camera_frame_;

  // Diagnostics: written by both sides and read by diagnose(), under stats_mutex_.
  std::mutex stats_mutex_;
  diagnostic_updater::Updater updater_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> frequency_;
  ros::Time last_image_, last_synced_image_;
  int unsynced_images_ = 0;  // images since the last synchronised frame
  ros::Time last_processed_;
  VisualOdometryResult last_result_;
  std::string last_problem_;
  std::string camera_model_;  // the last frame's lens model and what the node made of it
  int frames_ = 0, invalid_camera_info_ = 0, bad_images_ = 0, failures_ = 0, dropped_ = 0,
      bad_features_ = 0, camera_info_outages_ = 0;
  bool camera_info_outage_ = false;
  StreamCounters stream_counters_;
  LatencyWindow latency_ms_;
  LatencyWindow decode_ms_;  // per frame, compressed images only
  // Stereo frames whose scale fell back to mono_scale, and the last reason.
  int stereo_scale_fallbacks_ = 0;
  std::string last_scale_fallback_;
  // The map of world directions after the last frame, and how it served: priors the estimator
  // used or rejected, blank-wall frames, pairs whose rotation the map overruled (the map's own
  // counters are in map_stats_).
  std::vector<MapDirection> map_directions_;
  DirectionStructure map_structure_;
  DirectionMapStats map_stats_;
  int vp_priors_used_ = 0, vp_priors_rejected_ = 0, blank_wall_frames_ = 0, pairs_overruled_ = 0;
  int rotation_only_frames_ = 0;
  int keyframe_before_frames_ = 0;  // mono frames paired with the keyframe before the current

  InjectedLeak injected_leak_;  // the soak's own test only (scripts/soak --leak)
};

}  // namespace hybrid_vo
