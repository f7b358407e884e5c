#pragma once

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <thread>

#include <time.h>

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

// Runs body(0), ..., body(n - 1), each once, in any order and on any thread, and returns when
// all have run. The front end's stages split their independent parts (features, image cells)
// into such indices; each index writes its own slots of the output, so the results do not depend
// on which thread ran what. The default (empty) runs them in order on the calling thread.
using ParallelFor = std::function<void(int n, const std::function<void(int)>& body)>;
void run_indices(const ParallelFor& parallel, int n, const std::function<void(int)>& body);

// Indices [0, n) of a shared loop: the worker takes them one by one once it reaches the loop in
// its queue, and the caller takes the rest in join(). Destroying the handle joins (without
// rethrowing), so the body may use the caller's locals while the handle lives.
class SharedLoop {
 public:
  SharedLoop() = default;
  SharedLoop(SharedLoop&&) = default;
  SharedLoop& operator=(SharedLoop&& other);
  ~SharedLoop();
  // Runs the indices nobody has taken yet, waits for those the worker is running, and rethrows
  // the first exception of any of them. Nothing for an empty handle.
  void join();
  // Runs no index that has not started yet, and waits for those that have (their results are
  // to be ignored). Nothing for an empty handle.
  void cancel();

 private:
  friend class WorkerThread;
  struct State;
  // Takes and runs indices until none is left.
  static void run(State& state);
  void wait();

  std::shared_ptr<State> state_;
};

// One background thread that runs jobs in the order they are submitted: the front end's second
// core. A sequential worker runs each job at once in the calling thread (and leaves shared loops
// to the caller), so the same code serves both and gives the same results, the jobs being
// independent of when they run.
class WorkerThread {
 public:
  explicit WorkerThread(bool concurrent = true);
  ~WorkerThread();  // runs the jobs still queued, then joins
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

  WorkerJob submit(std::function<void()> job);
  // body(0), ..., body(n - 1) as a shared loop (see SharedLoop): the caller goes on with other
  // work and joins the loop when it needs its results.
  SharedLoop share(int n, std::function<void(int)> body);
  // share(n, body).join(): both threads run the indices, the worker once it is free.
  void parallel_for(int n, const std::function<void(int)>& body);
  // parallel_for as a ParallelFor, for the stages that take one.
  ParallelFor parallel();
  bool concurrent() const { return concurrent_; }
  // CPU time the worker thread has used (ms since it started; 0 for a sequential worker).
  double cpu_ms() const;

 private:
  void loop();
  void enqueue(std::packaged_task<void()> task);

  const bool concurrent_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::packaged_task<void()>> jobs_;
  bool stop_ = false;
  std::thread thread_;
  clockid_t clock_{};  // the worker's CPU clock
  bool has_clock_ = false;
};

// CPU time the calling thread has used (ms).
double thread_cpu_ms();

}  // namespace hybrid_vo
