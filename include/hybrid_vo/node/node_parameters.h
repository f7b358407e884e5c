#pragma once

#include <xmlrpcpp/XmlRpcValue.h>

#include <string>
#include <vector>

#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/node/stream_monitor.h"
#include "hybrid_vo/odometry/visual_odometry.h"

namespace hybrid_vo {

// Everything the node's private ROS parameters set (config/default.yaml lists them all, with the
// defaults below): the node's own settings and the odometry's options.
struct NodeParameters {
  NodeParameters();  // the defaults: preset hybrid and the node's VP support (6 segments)

  std::string odom_frame = "odom", base_frame = "base_link";
  bool publish_tf = true;
  bool stereo = false, approximate_sync = false;
  int queue_size = 10;
  bool compressed = false;  // image_transport: compressed (decoded by the node)
  bool rectify_fisheye = true;
  double rectified_fov_deg = 100.0;
  double camera_info_timeout = 2.0;
  bool feature_points = false, feature_lines = false;
  bool vins_format = false;  // feature_format: vins
  bool publish_debug_image = true, publish_markers = true;
  double min_frequency = 1.0, max_frequency = 100.0;
  int frame_queue_size = 1;
  // Frames that may wait beyond frame_queue_size while the node keeps up (FrameQueue): a slow
  // frame delays the next ones instead of losing them.
  int frame_queue_spare = 2;
  int path_max_poses = 5000;
  // OpenCV's own thread pool for the process (cv::setNumThreads); < 0 leaves OpenCV's default.
  // 1: none, since the front end splits its work over its two threads itself (doc/performance.md).
  int opencv_threads = 1;
  StreamMonitorOptions stream;
  // The choices as read, for the start-up log line.
  std::string preset = "hybrid", points = "klt", lines = "fld";
  VisualOdometryOptions odometry;
};

template <typename Visit>
void visit_fields(NodeParameters& p, Visit&& visit) {
  visit("queue_size", p.queue_size, at_least(1));
  visit("rectified_fov_deg", p.rectified_fov_deg, between(10.0, 170.0));
  visit("camera_info_timeout", p.camera_info_timeout, positive());
  visit("min_frequency", p.min_frequency, non_negative());
  visit("max_frequency", p.max_frequency, positive());
  visit("frame_queue_size", p.frame_queue_size, at_least(1));
  visit("frame_queue_spare", p.frame_queue_spare, non_negative());
  visit("path_max_poses", p.path_max_poses, non_negative());
  visit("max_frame_gap", p.stream.max_gap_s, positive());
  visit_fields(p.odometry, visit);
}

// Reads the parameters present in `params`, the node's private namespace as a struct (the
// parameter server's answer for it). A value of the wrong type, an unknown choice, or one that
// makes validate() fail is named in `warnings` and leaves that parameter's default. The preset
// is applied before the thresholds, so that those override it. Parameters the node does not know
// (a misspelt name) are named in `warnings` too, and so are the old names of renamed ones, which
// still take effect unless the new name is set as well (vp_tracker: direction_map).
NodeParameters read_node_parameters(const XmlRpc::XmlRpcValue& params,
                                    std::vector<std::string>* warnings);

// Every parameter read_node_parameters reads, in the order it reads them.
std::vector<std::string> node_parameter_names();

}  // namespace hybrid_vo
