#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>

namespace hybrid_vo {

// A submitted job. Destroying it waits for the job, so a job may use its caller's locals for as
// long as its handle lives, whatever path (or exception) leaves the caller.
class WorkerJob {
 public:
  WorkerJob() = default;
  explicit WorkerJob(std::future<void> done) : done_(std::move(done)) {}
  WorkerJob(WorkerJob&&) = default;
  WorkerJob& operator=(WorkerJob&& other) {
    wait();
    done_ = std::move(other.done_);
    return *this;
  }
  ~WorkerJob() { wait(); }
  void wait() {
    if (done_.valid()) done_.wait();
  }
  // Waits and rethrows what the job threw; nothing for an empty handle.
  void get() {
    if (done_.valid()) done_.get();
  }

 private:
  std::future<void> done_;
};

// One background thread that runs jobs in the order they are submitted: the front end's second
// core. A sequential worker runs each job at once in the calling thread, so the same code serves
// both (and gives the same results, the jobs being independent of when they run).
class WorkerThread {
 public:
  explicit WorkerThread(bool concurrent = true);
  ~WorkerThread();  // runs the jobs still queued, then joins
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

  WorkerJob submit(std::function<void()> job);
  bool concurrent() const { return concurrent_; }

 private:
  void loop();

  const bool concurrent_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::packaged_task<void()>> jobs_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace hybrid_vo
