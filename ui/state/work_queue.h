// One worker thread running queued jobs in order: what both workbench controllers use so that
// loading, fitting and solving never block the render thread. No GL, no ImGui.
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace calibench::ui {

class WorkQueue {
 public:
  // on_error(message) is called on the worker thread when a job throws; the queue goes on.
  explicit WorkQueue(std::function<void(const std::string&)> on_error);
  // Stop()s.
  ~WorkQueue();
  WorkQueue(const WorkQueue&) = delete;
  WorkQueue& operator=(const WorkQueue&) = delete;

  // Drops the jobs not yet started, waits for the running one and ends the thread; jobs enqueued
  // afterwards are dropped. Idempotent.
  void Stop();
  void Enqueue(std::function<void()> job);
  // Drops the jobs not yet started (a running one finishes).
  void DropQueued();
  // Blocks until no job is queued or running (tests, headless renders).
  void WaitIdle();
  // True while a job is queued or running.
  bool Busy() const;
  // From the next job on, the worker runs below normal priority (and the threads its jobs start):
  // on a machine with few cores the window's frames come first (a followed capture). Linux only
  // does it per thread; elsewhere, or refused, nothing changes.
  void LowerPriority();

 private:
  void Loop();

  std::function<void(const std::string&)> on_error_;
  mutable std::mutex mutex_;
  std::condition_variable queue_cv_, idle_cv_;
  std::deque<std::function<void()>> queue_;
  int running_jobs_ = 0;
  bool stop_ = false;
  std::thread worker_;  // last: starts once everything above is initialised
};

}  // namespace calibench::ui
