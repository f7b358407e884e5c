// The node's health on /diagnostics (diagnostic_updater): rate, tracking state, matches and
// inliers, timings, and counters of every skipped input and fault in the stream; and the
// watchdog that tells "no images" from "images without camera_info".
#include "hybrid_vo/node/vo_node.h"

#include <cstdio>
#include <initializer_list>
#include <utility>

namespace hybrid_vo {

bool VoNode::reject(const std::string& what, const std::string& reason, int* counter) {
  monitor_.reject();
  std::lock_guard<std::mutex> lock(stats_mutex_);
  ++*counter;
  last_problem_ = what + ": " + reason;
  ROS_WARN_THROTTLE(2.0, "hybrid_vo: skipping frame, %s", last_problem_.c_str());
  return false;
}

void VoNode::watchdog(const ros::TimerEvent&) {
  const ros::Time now = ros::Time::now();
  bool images_flow = false, frames_flow = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    images_flow =
        !last_image_.isZero() && (now - last_image_).toSec() < params_.camera_info_timeout;
    // A few images in a row, not one that is waiting for its camera_info after a pause.
    frames_flow = unsynced_images_ < 3 || (!last_synced_image_.isZero() &&
                                           (now - last_synced_image_).toSec() < params_.camera_info_timeout);
  }
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    if (images_flow && !frames_flow) {
      last_problem_ = "images arrive without a matching camera_info" +
                      std::string(params_.stereo ? " (or without their stereo partner)" : "");
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
  add_input(status);
  add_tracking(status);
  add_vp_tracks(status);
  add_counters(status);
}

void VoNode::add_input(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  status.add("image topic", image_topic_);
  status.add("image transport", params_.compressed ? "compressed (decoded by the node)" : "raw");
  status.add("camera model", camera_model_.empty() ? "no frame yet" : camera_model_);
  if (params_.compressed) {
    // Per frame (both images in stereo), from the last 200 frames.
    status.add("image decode p50 (ms)", decode_ms_.quantile(0.5));
    status.add("image decode p99 (ms)", decode_ms_.quantile(0.99));
  }
}

void VoNode::add_tracking(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  const VisualOdometryResult& r = last_result_;
  const RelativePoseEstimate& est = r.estimate.estimate;
  status.add("frames processed", frames_);
  status.add("last stamp", last_processed_.toSec());
  status.add("delay (s)", last_processed_.isZero() ? 0.0 : (ros::Time::now() - last_processed_).toSec());
  status.add("tracking state", to_string(r.status));
  status.add("point matches", r.num_point_matches);
  status.add("point inliers", est.num_point_inliers);
  status.add("vignetting at the corners (measured by the tracks)", r.vignetting_corner_gain);
  status.add("vignetting taken out for tracking", r.vignetting_corrected ? "yes" : "no");
  status.add("line matches", r.num_line_matches);
  status.add("line inliers", est.num_line_inliers);
  status.add("VP inliers", est.num_vp_inliers);
  status.add("junction inliers", est.num_junction_inliers);
  // This frame against the map of world directions: where its orientation came from, how many
  // directions it saw, by how much they corrected it, and whether the pair was a blank wall.
  status.add("orientation source", to_string(r.orientation.source));
  status.add("orientation: map directions seen", r.orientation.location.paired);
  status.add("orientation correction (deg)", r.orientation.correction_deg);
  status.add("blank wall", r.orientation.blank_wall);
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
  status.add("CPU, processing thread (ms)", r.stages.caller_cpu_ms);
  status.add("CPU, front end's second thread (ms)", r.stages.worker_cpu_ms);
  // The CPU budget (max_cpu_ms, 0: none): the recent frames' average against it, and the level
  // of work the frame was done at (cpu_budget.h: 0 everything, 3 the lightest).
  status.add("CPU per frame, recent average (ms)", r.average_cpu_ms);
  status.add("CPU budget (ms)", params_.odometry.budget.max_cpu_ms);
  status.add("work level", r.work_level);
  status.add("segment tracks found", r.line_tracking.matched);
  status.add("segment tracks started", r.line_tracking.started);
}

void VoNode::add_vp_tracks(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  // The map of world directions: each direction's uncertainty and support, its structure, how
  // often it held the orientation, and how its priors fared in the estimator.
  int confirmed = 0;
  for (const MapDirection& d : map_directions_) {
    confirmed += d.confirmed;
    char key[64], value[160];
    std::snprintf(key, sizeof(key), "map direction %d", d.id);
    std::snprintf(value, sizeof(value),
                  "sigma %.3f deg, hits %d, last chi2 %.2f, disagreements %d in a row, %d in "
                  "total%s",
                  d.sigma_deg(), d.hits, d.last_chi2, d.disagreements, d.total_disagreements,
                  d.confirmed ? "" : ", not yet confirmed");
    status.add(key, value);
  }
  status.add("map directions", static_cast<int>(map_directions_.size()));
  status.add("map directions confirmed", confirmed);
  status.add("map Manhattan triads", static_cast<int>(map_structure_.triads.size()));
  status.add("map Atlanta verticals", static_cast<int>(map_structure_.verticals.size()));
  status.add("frames held by the map", map_stats_.located);
  status.add("map re-acquisitions", map_stats_.reacquisitions);
  status.add("map corrections rejected", map_stats_.rejected);
  status.add("pairs overruled by the map", pairs_overruled_);
  status.add("blank-wall frames", blank_wall_frames_);
  status.add("rotation-only frames (no translation seen)", rotation_only_frames_);
  status.add("frames paired with the keyframe before", keyframe_before_frames_);
  status.add("VP priors used", vp_priors_used_);
  status.add("VP priors rejected by the gate", vp_priors_rejected_);
}

void VoNode::add_counters(diagnostic_updater::DiagnosticStatusWrapper& status) const {
  using Counts = std::initializer_list<std::pair<const char*, int>>;
  // Input that could not be used.
  for (const auto& [key, count] : Counts{{"invalid camera_info", invalid_camera_info_},
                                         {"bad images", bad_images_},
                                         {"bad feature messages", bad_features_},
                                         {"frames without pose", failures_},
                                         {"pairs without a covariance",
                                          last_result_.pose_covariance_gaps},
                                         {"incomplete frames dropped", dropped_}})
    status.add(key, count);
  // Load: frames dropped because the processing thread was busy, and the time from a frame's
  // arrival to its publication over the last 200 frames.
  status.add("frames dropped (queue full)", queue_->dropped());
  status.add("queue length", queue_->size());
  status.add("latency p50 (ms)", latency_ms_.quantile(0.5));
  status.add("latency p99 (ms)", latency_ms_.quantile(0.99));
  // Faults in the stream (stream_monitor.h).
  const StreamCounters& c = stream_counters_;
  for (const auto& [key, count] : Counts{{"time jumps (resets)", c.backwards},
                                         {"time gaps (restarts)", c.gaps},
                                         {"image size changes (restarts)", c.size_changes},
                                         {"restarts after rejected input", c.after_faults},
                                         {"duplicate stamps skipped", c.duplicates},
                                         {"late frames skipped", c.late},
                                         {"camera_info outages", camera_info_outages_}})
    status.add(key, count);
}

}  // namespace hybrid_vo
