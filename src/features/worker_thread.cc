#include "hybrid_vo/features/worker_thread.h"

#include <pthread.h>
#include <time.h>

#include <atomic>
#include <utility>

namespace hybrid_vo {
namespace {

double cpu_ms_of(clockid_t clock) {
  timespec t{};
  if (clock_gettime(clock, &t) != 0) return 0.0;
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

}  // namespace

void run_indices(const ParallelFor& parallel, int n, const std::function<void(int)>& body) {
  if (n <= 0) return;
  if (parallel) {
    parallel(n, body);
    return;
  }
  for (int i = 0; i < n; ++i) body(i);
}

struct SharedLoop::State {
  std::function<void(int)> body;
  int n = 0;
  std::atomic<int> next{0};
  std::mutex mutex;
  std::condition_variable all_done;
  int done = 0;
  std::exception_ptr error;
};

void SharedLoop::run(State& state) {
  for (;;) {
    // An index is claimed before the body is touched: once all are claimed, a late worker
    // returns without using the body, whose captures may be gone by then.
    const int i = state.next.fetch_add(1);
    if (i >= state.n) return;
    std::exception_ptr error;
    try {
      state.body(i);
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(state.mutex);
    if (error && !state.error) state.error = error;
    if (++state.done == state.n) state.all_done.notify_all();
  }
}

void SharedLoop::wait() {
  if (!state_) return;
  run(*state_);
  std::unique_lock<std::mutex> lock(state_->mutex);
  state_->all_done.wait(lock, [this] { return state_->done == state_->n; });
}

void SharedLoop::join() {
  if (!state_) return;
  wait();
  const std::exception_ptr error = state_->error;
  state_.reset();
  if (error) std::rethrow_exception(error);
}

void SharedLoop::cancel() {
  if (!state_) return;
  const int first_untaken = state_->next.exchange(state_->n);
  if (first_untaken < state_->n) {
    std::lock_guard<std::mutex> lock(state_->mutex);
    state_->done += state_->n - first_untaken;
  }
  wait();
  state_.reset();
}

SharedLoop& SharedLoop::operator=(SharedLoop&& other) {
  wait();
  state_ = std::move(other.state_);
  return *this;
}

SharedLoop::~SharedLoop() { wait(); }

WorkerThread::WorkerThread(bool concurrent) : concurrent_(concurrent) {
  if (!concurrent_) return;
  thread_ = std::thread([this] { loop(); });
  has_clock_ = pthread_getcpuclockid(thread_.native_handle(), &clock_) == 0;
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
  enqueue(std::move(task));
  return WorkerJob(std::move(done));
}

void WorkerThread::enqueue(std::packaged_task<void()> task) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_.push_back(std::move(task));
  }
  wake_.notify_one();
}

SharedLoop WorkerThread::share(int n, std::function<void(int)> body) {
  SharedLoop loop;
  if (n <= 0) return loop;
  loop.state_ = std::make_shared<SharedLoop::State>();
  loop.state_->body = std::move(body);
  loop.state_->n = n;
  // The worker's part holds the state, not the handle: it may start after the caller has run
  // every index and left. Nobody waits for it (a WorkerJob would), only for the indices.
  if (concurrent_)
    enqueue(std::packaged_task<void()>([state = loop.state_] { SharedLoop::run(*state); }));
  return loop;
}

void WorkerThread::parallel_for(int n, const std::function<void(int)>& body) {
  share(n, body).join();
}

ParallelFor WorkerThread::parallel() {
  return [this](int n, const std::function<void(int)>& body) { parallel_for(n, body); };
}

double WorkerThread::cpu_ms() const {
  return has_clock_ ? cpu_ms_of(clock_) : 0.0;
}

double thread_cpu_ms() { return cpu_ms_of(CLOCK_THREAD_CPUTIME_ID); }

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
