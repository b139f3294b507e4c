// One worker thread for everything a workbench controller does off the window thread: loading,
// fitting, solving (queued jobs, in order) and, below them, the long and the periodic work — a
// rig's joint solve one camera at a time, a followed capture's looks — as background jobs that run
// only while no queued job waits (docs/architecture.md, "Threads"). No GL, no ImGui.
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace calibench::ui {

class WorkQueue {
 public:
  // on_error(message) is called on the worker thread when a job throws; the queue goes on.
  explicit WorkQueue(std::function<void(const std::string&)> on_error);
  // Stop()s.
  ~WorkQueue();
  WorkQueue(const WorkQueue&) = delete;
  WorkQueue& operator=(const WorkQueue&) = delete;

  // Drops the jobs not yet started (background ones too), waits for the running one and ends the
  // thread; jobs enqueued afterwards are dropped. Idempotent.
  void Stop();
  void Enqueue(std::function<void()> job);
  // A background job of `lane` ("rig", "follow"): it runs once no queued job waits and `delay_s`
  // [s] has passed, so that a brush stroke's refit never waits behind more than one background
  // step. A step that has more to do enqueues its successor itself (from the job: atomic with
  // CancelBackground).
  void EnqueueBackground(const std::string& lane, std::function<void()> job, double delay_s = 0);
  // Drops `lane`'s background jobs not yet started, after waiting for its running one (which may
  // enqueue a successor: dropped too). From the worker itself it does not wait (the running job is
  // the caller).
  void CancelBackground(const std::string& lane);
  // True while `lane` has a background job queued or running.
  bool BackgroundPending(const std::string& lane) const;
  // Drops the queued jobs not yet started (a running one finishes; background jobs stay).
  void DropQueued();
  // Blocks until no job is queued or running and no background job is due now (one waiting for
  // its delay, a followed capture's next look, does not count): tests, headless renders. From a
  // background job on the worker it returns at once: nothing else can run meanwhile.
  void WaitIdle();
  // True while a queued job waits or runs (background jobs show their own progress).
  bool Busy() const;
  // True on the worker thread.
  bool OnWorker() const { return std::this_thread::get_id() == worker_id_; }
  // From the next job on, the worker runs below normal priority (and the threads its jobs start):
  // on a machine with few cores the window's frames come first (a followed capture). Linux only
  // does it per thread; elsewhere, or refused, nothing changes.
  void LowerPriority();

 private:
  using Clock = std::chrono::steady_clock;
  struct BackgroundJob {
    std::string lane;
    std::function<void()> job;
    Clock::time_point due;
  };
  void Loop();
  // The next job to run, or none yet (lock held); *wake: when a background job falls due.
  bool TakeJob(std::function<void()>* job, std::string* lane, Clock::time_point* wake);
  bool BackgroundDue(Clock::time_point now) const;  // lock held

  std::function<void(const std::string&)> on_error_;
  mutable std::mutex mutex_;
  std::condition_variable queue_cv_, idle_cv_;
  std::deque<std::function<void()>> queue_;
  std::vector<BackgroundJob> background_;
  int running_jobs_ = 0;
  std::string running_lane_;  // the running job's lane; empty for a queued job
  bool stop_ = false;
  std::thread::id worker_id_;
  std::thread worker_;  // last: starts once everything above is initialised
};

}  // namespace calibench::ui
