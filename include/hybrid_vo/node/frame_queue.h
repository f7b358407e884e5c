#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <utility>

namespace hybrid_vo {

// The hand-over between the subscriber callbacks and the node's processing thread. A callback
// never waits: when the queue is full the oldest frame is dropped (and counted), so that under
// overload the node works on recent frames with a bounded delay instead of an ever older backlog
// (rtabmap's odometry thread keeps one frame by default for the same reason). Frames leave in the
// order they came, so the processing thread never sees a frame before an earlier arrival.
template <typename T>
class FrameQueue {
 public:
  explicit FrameQueue(size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  // Appends `item`; returns how many frames were dropped to make room (0 or 1).
  int push(T item) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return 0;
    int dropped = 0;
    while (items_.size() >= capacity_) {
      items_.pop_front();
      ++dropped;
    }
    items_.push_back(std::move(item));
    ++pushed_;
    dropped_ += dropped;
    ready_.notify_one();
    return dropped;
  }

  // Waits for the oldest frame; false once close() was called.
  bool pop(T* item) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait(lock, [&] { return closed_ || !items_.empty(); });
    if (closed_) return false;
    *item = std::move(items_.front());
    items_.pop_front();
    return true;
  }

  // Wakes the consumer and refuses every later push and pop (shutdown).
  void close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    items_.clear();
    ready_.notify_all();
  }

  // Forgets the waiting frames without counting them as dropped (e.g. on a reset request).
  void clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    items_.clear();
  }

  size_t capacity() const { return capacity_; }
  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  uint64_t pushed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pushed_;
  }
  uint64_t dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }

 private:
  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<T> items_;
  bool closed_ = false;
  uint64_t pushed_ = 0, dropped_ = 0;
};

}  // namespace hybrid_vo
