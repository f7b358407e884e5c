#pragma once

#include <string>

namespace hybrid_vo {

// Faults of an image stream that the node survives (doc/reliability.md), decided per
// frame from its stamp and image size before any processing, without ROS.
struct StreamMonitorOptions {
  // A frame newer than the last one by more than this (s) starts a new keyframe chain: the motion
  // across a gap (a camera_info outage, a paused driver, a clock jumping forwards) is unknown, and
  // tracking across it would pair frames that may share nothing.
  double max_gap_s = 1.0;
};

enum class StreamEvent {
  kFirst,       // the first frame (or the first after a reset)
  kNext,        // pairs with the previous frames as usual
  kDuplicate,   // the same stamp as the last frame: skipped
  kLate,        // older than the last frame by at most max_gap_s (out of order): skipped
  kBackwards,   // older by more: the clock went back (a bag loop): the odometry resets
  kGap,         // newer by more than max_gap_s: the chain restarts, the pose is kept
  kSizeChange,  // another image size than the last processed frame's: the chain restarts
  kAfterFault,  // the frame after rejected input (bad image, camera_info, features): restarts
};
const char* to_string(StreamEvent event);

// True for the events whose frame is not processed at all.
inline bool skips(StreamEvent e) { return e == StreamEvent::kDuplicate || e == StreamEvent::kLate; }
// True for the events that start a new keyframe chain while keeping the pose.
inline bool restarts(StreamEvent e) {
  return e == StreamEvent::kGap || e == StreamEvent::kSizeChange || e == StreamEvent::kAfterFault;
}

struct StreamCounters {
  int duplicates = 0, late = 0, backwards = 0, gaps = 0, size_changes = 0, after_faults = 0;
  int restarts() const { return gaps + size_changes + after_faults; }
};

class StreamMonitor {
 public:
  explicit StreamMonitor(const StreamMonitorOptions& options = {}) : options_(options) {}

  // What the next valid frame is, counted. Every frame that is not skipped becomes the reference
  // for the next frame's stamp checks. (The node rejects corrupt input before it gets here, so
  // that a broken message's stamp or size never counts as an event.)
  StreamEvent classify(double stamp, int width, int height);
  // The frame was processed: its size is the reference for the next size check.
  void accept(int width, int height);
  // Input was rejected: the next frame restarts the chain, so that no motion is estimated
  // across the bad input.
  void reject() { restart_pending_ = true; }
  // Forgets the stream (reset service, bag loop); the counters stay.
  void reset();

  // A sentence about the last classified event, e.g. "time jumped forwards by 10.0 s".
  const std::string& description() const { return description_; }
  const StreamCounters& counters() const { return counters_; }
  const StreamMonitorOptions& options() const { return options_; }

 private:
  StreamMonitorOptions options_;
  bool have_stamp_ = false, have_size_ = false, restart_pending_ = false;
  double last_stamp_ = 0.0;
  int width_ = 0, height_ = 0;
  StreamCounters counters_;
  std::string description_;
};

}  // namespace hybrid_vo
