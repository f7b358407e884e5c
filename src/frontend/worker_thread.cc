#include "hybrid_vo/frontend/worker_thread.h"

#include <utility>

namespace hybrid_vo {

WorkerThread::WorkerThread(bool concurrent) : concurrent_(concurrent) {
  if (concurrent_) thread_ = std::thread([this] { loop(); });
}

WorkerThread::~WorkerThread() {
  if (!concurrent_) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

WorkerJob WorkerThread::submit(std::function<void()> job) {
  std::packaged_task<void()> task(std::move(job));
  std::future<void> done = task.get_future();
  if (!concurrent_) {
    task();
    return WorkerJob(std::move(done));
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_.push_back(std::move(task));
  }
  wake_.notify_one();
  return WorkerJob(std::move(done));
}

void WorkerThread::loop() {
  for (;;) {
    std::packaged_task<void()> task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || !jobs_.empty(); });
      if (jobs_.empty()) return;  // stopping, and nothing left to run
      task = std::move(jobs_.front());
      jobs_.pop_front();
    }
    task();
  }
}

}  // namespace hybrid_vo
