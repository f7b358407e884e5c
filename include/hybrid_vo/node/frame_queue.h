#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <utility>

namespace hybrid_vo {

// The hand-over between the subscriber callbacks and the node's processing thread. A callback
// never waits: when the queue is full the oldest frame is dropped (and counted), so that under
// overload the node works on recent frames with a bounded delay instead of an ever older backlog
// (rtabmap's odometry thread keeps one frame by default for the same reason). Frames leave in the
// order they came, so the processing thread never sees a frame before an earlier arrival.
//
// `spare` more frames may wait while the consumer keeps up (the median of its last nine times per
// frame below the mean time between the last nine arrivals): one slow frame then
// delays the next ones instead of losing them, as a replayed bag or a robot's camera expects
// (a keyframe or the first frame may take a few periods). Under overload the
// consumer does not keep up, the spare slots close and the delay stays bounded by `capacity`.
template <typename T>
class FrameQueue {
 public:
  // Seconds on a monotonic clock; replaceable for tests.
  using Clock = std::function<double()>;

  explicit FrameQueue(size_t capacity, size_t spare = 0, Clock clock = steady_seconds)
      : capacity_(capacity < 1 ? 1 : capacity), spare_(spare), clock_(std::move(clock)) {}

  // Appends `item`; returns how many frames were dropped to make room (more than one when the
  // spare slots have just closed).
  int push(T item) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return 0;
    arrivals_[next_arrival_] = clock_();
    next_arrival_ = (next_arrival_ + 1) % arrivals_.size();
    arrival_count_ = std::min(arrival_count_ + 1, arrivals_.size());
    const size_t limit = capacity_ + (keeps_up() ? spare_ : 0);
    int dropped = 0;
    while (items_.size() >= limit) {
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
    last_pop_ = clock_();
    return true;
  }

  // The consumer is done with the frame it popped last: its time since pop() tells whether it
  // keeps up. Until it has said so once, it is taken to keep up (keeps_up()).
  void finished() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (last_pop_ >= 0.0) service_time_.add(clock_() - last_pop_);
    last_pop_ = -1.0;
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
  size_t spare() const { return spare_; }
  // Whether the consumer keeps up on average, so that the spare slots are open.
  bool keeping_up() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return keeps_up();
  }
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
  static double steady_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  // The median of the last nine samples.
  class RecentMedian {
   public:
    void add(double sample) {
      if (!(sample >= 0.0)) return;
      samples_[next_] = sample;
      next_ = (next_ + 1) % samples_.size();
      count_ = std::min(count_ + 1, samples_.size());
    }
    bool known() const { return count_ > 0; }
    double median() const {
      std::array<double, 9> sorted = samples_;
      std::nth_element(sorted.begin(), sorted.begin() + count_ / 2, sorted.begin() + count_);
      return sorted[count_ / 2];
    }

   private:
    std::array<double, 9> samples_{};
    size_t next_ = 0, count_ = 0;
  };
  // The mean time between the last nine arrivals (a sender's bursts do not move it, as they
  // would a median), against the median of the consumer's last nine times per frame (one slow
  // frame does not move it, an overload does within five). Until both are measured the spare slots
  // are open: a node's first frames are slow (set-up, the first keyframe), which is no overload.
  bool keeps_up() const {
    if (arrival_count_ < 2 || !service_time_.known()) return true;
    const size_t newest = (next_arrival_ + arrivals_.size() - 1) % arrivals_.size();
    const size_t oldest = (next_arrival_ + arrivals_.size() - arrival_count_) % arrivals_.size();
    const double interval = (arrivals_[newest] - arrivals_[oldest]) / (arrival_count_ - 1);
    return service_time_.median() < interval;
  }

  const size_t capacity_, spare_;
  const Clock clock_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<T> items_;
  bool closed_ = false;
  uint64_t pushed_ = 0, dropped_ = 0;
  double last_pop_ = -1.0;  // seconds (negative: none)
  RecentMedian service_time_;
  std::array<double, 9> arrivals_{};  // the last pushes' times, a ring
  size_t next_arrival_ = 0, arrival_count_ = 0;
};

}  // namespace hybrid_vo
