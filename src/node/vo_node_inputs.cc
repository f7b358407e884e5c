// The node's inputs: image and camera_info subscriptions (mono or stereo, exact or approximate
// sync), the optional feature topics, and the assembly of frames from their parts. Callbacks
// only assemble frames and queue the complete ones for the processing thread.
#include "hybrid_vo/node/vo_node.h"

namespace hybrid_vo {

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
  add_images(image, info, nullptr, nullptr);
}

void VoNode::stereo_callback(const sensor_msgs::ImageConstPtr& left,
                             const sensor_msgs::CameraInfoConstPtr& left_info,
                             const sensor_msgs::ImageConstPtr& right,
                             const sensor_msgs::CameraInfoConstPtr& right_info) {
  add_images(left, left_info, right, right_info);
}

void VoNode::add_images(const sensor_msgs::ImageConstPtr& left,
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

// A feature message is one part of its frame (DESIGN.md: stamped like its image).
template <class MessagePtr>
void VoNode::add_features(const MessagePtr& msg, MessagePtr Frame::*part, bool Frame::*have) {
  std::lock_guard<std::mutex> lock(mutex_);
  Frame& f = pending(msg->header.stamp);
  f.*part = msg;
  f.*have = true;
  try_process(msg->header.stamp);
}

void VoNode::points_callback(const FeaturePoints::ConstPtr& msg) {
  add_features(msg, &Frame::points, &Frame::have_points);
}

void VoNode::lines_callback(const FeatureLines::ConstPtr& msg) {
  add_features(msg, &Frame::lines, &Frame::have_lines);
}

void VoNode::vins_points_callback(const sensor_msgs::PointCloud::ConstPtr& msg) {
  add_features(msg, &Frame::vins_points, &Frame::have_points);
}

void VoNode::vins_lines_callback(const sensor_msgs::PointCloud::ConstPtr& msg) {
  add_features(msg, &Frame::vins_lines, &Frame::have_lines);
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

}  // namespace hybrid_vo
