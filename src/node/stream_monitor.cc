#include "hybrid_vo/node/stream_monitor.h"

#include <cstdio>

namespace hybrid_vo {
namespace {

std::string seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f s", s);
  return text;
}

}  // namespace

const char* to_string(StreamEvent event) {
  switch (event) {
    case StreamEvent::kFirst:
      return "first frame";
    case StreamEvent::kNext:
      return "next frame";
    case StreamEvent::kDuplicate:
      return "duplicate stamp";
    case StreamEvent::kLate:
      return "late frame";
    case StreamEvent::kBackwards:
      return "time went backwards";
    case StreamEvent::kGap:
      return "time gap";
    case StreamEvent::kSizeChange:
      return "image size changed";
    case StreamEvent::kAfterFault:
      return "after rejected input";
  }
  return "unknown";
}

StreamEvent StreamMonitor::classify(double stamp, int width, int height) {
  StreamEvent event = StreamEvent::kNext;
  description_.clear();
  if (!have_stamp_) {
    event = StreamEvent::kFirst;
  } else if (stamp == last_stamp_) {
    ++counters_.duplicates;
    description_ = "duplicate stamp " + seconds(stamp) + ": frame skipped";
    return StreamEvent::kDuplicate;
  } else if (stamp < last_stamp_) {
    const double back = last_stamp_ - stamp;
    if (back <= options_.max_gap_s) {
      ++counters_.late;
      description_ = "frame " + seconds(back) + " older than the last one: skipped";
      return StreamEvent::kLate;
    }
    ++counters_.backwards;
    description_ = "time went backwards by " + seconds(back) + ": odometry reset";
    event = StreamEvent::kBackwards;
    restart_pending_ = false;
    have_size_ = false;
  } else if (have_size_ && (width != width_ || height != height_)) {
    ++counters_.size_changes;
    description_ = "the image size changed from " + std::to_string(width_) + "x" +
                   std::to_string(height_) + " to " + std::to_string(width) + "x" +
                   std::to_string(height) + ": keyframe restarted";
    event = StreamEvent::kSizeChange;
  } else if (stamp - last_stamp_ > options_.max_gap_s) {
    ++counters_.gaps;
    description_ = "time jumped forwards by " + seconds(stamp - last_stamp_) +
                   ": keyframe restarted, the motion across the gap is unknown";
    event = StreamEvent::kGap;
  } else if (restart_pending_) {
    ++counters_.after_faults;
    description_ = "keyframe restarted after rejected input";
    event = StreamEvent::kAfterFault;
  }
  have_stamp_ = true;
  last_stamp_ = stamp;
  return event;
}

void StreamMonitor::accept(int width, int height) {
  have_size_ = true;
  width_ = width;
  height_ = height;
  restart_pending_ = false;
}

void StreamMonitor::reset() {
  have_stamp_ = have_size_ = restart_pending_ = false;
  description_.clear();
}

}  // namespace hybrid_vo
