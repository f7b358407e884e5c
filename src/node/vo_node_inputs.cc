// The node's inputs: image and camera_info subscriptions (mono or stereo, exact or approximate
// sync, raw or compressed images), the optional feature topics, and the assembly of frames from
// their parts. Callbacks only assemble frames and queue the complete ones for the processing
// thread, which decodes compressed images (vo_node.cc).
#include "hybrid_vo/node/vo_node.h"

namespace hybrid_vo {

void VoNode::subscribe() {
  const std::string left = params_.stereo ? "left/image" : "image";
  const std::string left_info = params_.stereo ? "left/camera_info" : "camera_info";
  // TCP_NODELAY: without it Nagle's algorithm holds a small camera_info (or the last segment of
  // an image) until the previous one is acknowledged, which adds up to 40 ms per frame.
  const ros::TransportHints no_delay = ros::TransportHints().tcpNoDelay();
  // The compressed topic is image_transport's: the resolved (remapped) image topic plus
  // "/compressed".
  const std::string suffix = params_.compressed ? "/compressed" : "";
  image_topic_ = nh_.resolveName(left) + suffix;
  left_info_sub_.subscribe(nh_, left_info, params_.queue_size, no_delay);
  if (params_.stereo) right_info_sub_.subscribe(nh_, "right/camera_info", params_.queue_size, no_delay);
  if (params_.compressed) {
    left_compressed_sub_.subscribe(nh_, image_topic_, params_.queue_size, no_delay);
    if (params_.stereo)
      right_compressed_sub_.subscribe(nh_, nh_.resolveName("right/image") + suffix, params_.queue_size,
                                      no_delay);
    synchronise(&left_compressed_sub_, &right_compressed_sub_);
    arrival_sub_ = nh_.subscribe(image_topic_, 1,
                                 &VoNode::image_arrived<sensor_msgs::CompressedImage>, this,
                                 no_delay);
  } else {
    left_sub_.subscribe(nh_, image_topic_, params_.queue_size, no_delay);
    if (params_.stereo) right_sub_.subscribe(nh_, "right/image", params_.queue_size, no_delay);
    synchronise(&left_sub_, &right_sub_);
    arrival_sub_ =
        nh_.subscribe(image_topic_, 1, &VoNode::image_arrived<sensor_msgs::Image>, this, no_delay);
  }
  if (params_.feature_points) {
    points_sub_ = params_.vins_format ? nh_.subscribe("features/points", params_.queue_size,
                                               &VoNode::vins_points_callback, this, no_delay)
                               : nh_.subscribe("features/points", params_.queue_size,
                                               &VoNode::points_callback, this, no_delay);
  }
  if (params_.feature_lines) {
    lines_sub_ = params_.vins_format ? nh_.subscribe("features/lines", params_.queue_size,
                                              &VoNode::vins_lines_callback, this, no_delay)
                              : nh_.subscribe("features/lines", params_.queue_size,
                                              &VoNode::lines_callback, this, no_delay);
  }
}

template <class ImageMsg>
void VoNode::synchronise(message_filters::Subscriber<ImageMsg>* left,
                         message_filters::Subscriber<ImageMsg>* right) {
  namespace policies = message_filters::sync_policies;
  using Info = sensor_msgs::CameraInfo;
  if (params_.stereo && params_.approximate_sync) {
    using Policy = policies::ApproximateTime<ImageMsg, Info, ImageMsg, Info>;
    auto sync = std::make_shared<message_filters::Synchronizer<Policy>>(
        Policy(params_.queue_size), *left, left_info_sub_, *right, right_info_sub_);
    sync->registerCallback(&VoNode::stereo_callback<ImageMsg>, this);
    sync_ = sync;
  } else if (params_.stereo) {
    using Policy = policies::ExactTime<ImageMsg, Info, ImageMsg, Info>;
    auto sync = std::make_shared<message_filters::Synchronizer<Policy>>(
        Policy(params_.queue_size), *left, left_info_sub_, *right, right_info_sub_);
    sync->registerCallback(&VoNode::stereo_callback<ImageMsg>, this);
    sync->registerDropCallback(&VoNode::stereo_dropped<ImageMsg>, this);
    sync_ = sync;
  } else if (params_.approximate_sync) {
    using Policy = policies::ApproximateTime<ImageMsg, Info>;
    auto sync = std::make_shared<message_filters::Synchronizer<Policy>>(Policy(params_.queue_size),
                                                                        *left, left_info_sub_);
    sync->registerCallback(&VoNode::mono_callback<ImageMsg>, this);
    sync_ = sync;
  } else {
    using Policy = policies::ExactTime<ImageMsg, Info>;
    auto sync = std::make_shared<message_filters::Synchronizer<Policy>>(Policy(params_.queue_size),
                                                                        *left, left_info_sub_);
    sync->registerCallback(&VoNode::mono_callback<ImageMsg>, this);
    sync->registerDropCallback(&VoNode::mono_dropped<ImageMsg>, this);
    sync_ = sync;
  }
}

void VoNode::count_incomplete(int frames) {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  dropped_ += frames;
}

template <class ImageMsg>
void VoNode::mono_dropped(const boost::shared_ptr<const ImageMsg>&,
                          const sensor_msgs::CameraInfoConstPtr&) {
  count_incomplete(1);
}

template <class ImageMsg>
void VoNode::stereo_dropped(const boost::shared_ptr<const ImageMsg>&,
                            const sensor_msgs::CameraInfoConstPtr&,
                            const boost::shared_ptr<const ImageMsg>&,
                            const sensor_msgs::CameraInfoConstPtr&) {
  count_incomplete(1);
}

template <class ImageMsg>
void VoNode::image_arrived(const boost::shared_ptr<const ImageMsg>&) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_image_ = ros::Time::now();
  ++unsynced_images_;
}

VoNode::Frame& VoNode::pending(const ros::Time& stamp) {
  Frame& f = pending_[stamp];
  f.stamp = stamp;
  // A bounded wait: features or images that never complete a frame are dropped, oldest first.
  while (pending_.size() > 50) {
    pending_.erase(pending_.begin());
    count_incomplete(1);
  }
  return pending_[stamp];
}

template <class ImageMsg>
void VoNode::mono_callback(const boost::shared_ptr<const ImageMsg>& image,
                           const sensor_msgs::CameraInfoConstPtr& info) {
  add_images(image->header, FrameImage(image), info, FrameImage(), nullptr);
}

template <class ImageMsg>
void VoNode::stereo_callback(const boost::shared_ptr<const ImageMsg>& left,
                             const sensor_msgs::CameraInfoConstPtr& left_info,
                             const boost::shared_ptr<const ImageMsg>& right,
                             const sensor_msgs::CameraInfoConstPtr& right_info) {
  add_images(left->header, FrameImage(left), left_info, FrameImage(right), right_info);
}

void VoNode::add_images(const std_msgs::Header& header, const FrameImage& left,
                        const sensor_msgs::CameraInfoConstPtr& left_info, const FrameImage& right,
                        const sensor_msgs::CameraInfoConstPtr& right_info) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_synced_image_ = ros::Time::now();
  unsynced_images_ = 0;
  Frame& f = pending(header.stamp);
  f.left = left;
  f.left_info = left_info;
  f.right = right;
  f.right_info = right_info;
  f.frame_id = header.frame_id;
  f.have_images = true;
  try_process(header.stamp);
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
  if (!f.have_images || (params_.feature_points && !f.have_points) ||
      (params_.feature_lines && !f.have_lines))
    return;
  Frame frame = f;
  frame.received = std::chrono::steady_clock::now();
  // Everything up to this stamp is either this frame or can no longer be completed in order.
  int incomplete = 0;
  for (auto p = pending_.begin(); p != pending_.end() && p->first <= stamp;) {
    if (p->first < stamp) ++incomplete;
    p = pending_.erase(p);
  }
  if (incomplete > 0) count_incomplete(incomplete);
  queue_->push(std::move(frame));
}

}  // namespace hybrid_vo
