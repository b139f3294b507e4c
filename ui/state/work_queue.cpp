#include "ui/state/work_queue.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <exception>

#include "core/base/types.h"

namespace calibench::ui {
namespace {
constexpr int kJobNiceness = 10;  // 0 normal .. 19 lowest
}  // namespace

WorkQueue::WorkQueue(std::function<void(const std::string&)> on_error)
    : on_error_(std::move(on_error)), worker_([this] { Loop(); }) {
  // Read by the worker's jobs only, which start after this (Enqueue's lock orders them).
  worker_id_ = worker_.get_id();
}

WorkQueue::~WorkQueue() { Stop(); }

void WorkQueue::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    queue_.clear();
    background_.clear();
  }
  queue_cv_.notify_all();
  if (worker_.joinable() && !OnWorker()) worker_.join();
  idle_cv_.notify_all();
}

void WorkQueue::Enqueue(std::function<void()> job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) return;
    queue_.push_back(std::move(job));
  }
  queue_cv_.notify_one();
}

void WorkQueue::EnqueueBackground(const std::string& lane, std::function<void()> job,
                                  double delay_s) {
  CALIBENCH_CHECK(!lane.empty());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) return;
    background_.push_back({lane, std::move(job),
                           Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(delay_s))});
  }
  queue_cv_.notify_one();
}

void WorkQueue::CancelBackground(const std::string& lane) {
  std::unique_lock<std::mutex> lock(mutex_);
  // Waiting and dropping under one hold of the lock: the worker cannot start the successor the
  // running step enqueued in between.
  if (!OnWorker()) idle_cv_.wait(lock, [&] { return running_lane_ != lane; });
  std::erase_if(background_, [&](const BackgroundJob& job) { return job.lane == lane; });
  lock.unlock();
  idle_cv_.notify_all();
}

bool WorkQueue::BackgroundPending(const std::string& lane) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_lane_ == lane ||
         std::any_of(background_.begin(), background_.end(),
                     [&](const BackgroundJob& job) { return job.lane == lane; });
}

void WorkQueue::DropQueued() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.clear();
  }
  idle_cv_.notify_all();
}

bool WorkQueue::BackgroundDue(Clock::time_point now) const {
  return std::any_of(background_.begin(), background_.end(),
                     [&](const BackgroundJob& job) { return job.due <= now; });
}

void WorkQueue::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (OnWorker()) {
    // Only a background job can get here without deadlock: it ran because nothing was queued.
    CALIBENCH_CHECK(!running_lane_.empty() && "WaitIdle from a queued job would wait for itself");
    return;
  }
  idle_cv_.wait(lock, [&] {
    return stop_ || (queue_.empty() && running_jobs_ == 0 && !BackgroundDue(Clock::now()));
  });
}

bool WorkQueue::Busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !queue_.empty() || (running_jobs_ > 0 && running_lane_.empty());
}

void WorkQueue::LowerPriority() {
  // On the worker itself: Linux's nice value is per thread, and threads it starts inherit it.
  Enqueue([] { setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kJobNiceness); });
}

bool WorkQueue::TakeJob(std::function<void()>* job, std::string* lane, Clock::time_point* wake) {
  if (!queue_.empty()) {
    *job = std::move(queue_.front());
    queue_.pop_front();
    lane->clear();
    return true;
  }
  if (background_.empty()) return false;
  // The earliest due background job; in enqueue order among those due.
  auto next = std::min_element(
      background_.begin(), background_.end(),
      [](const BackgroundJob& a, const BackgroundJob& b) { return a.due < b.due; });
  if (next->due > Clock::now()) {
    *wake = next->due;
    return false;
  }
  *job = std::move(next->job);
  *lane = next->lane;
  background_.erase(next);
  return true;
}

void WorkQueue::Loop() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      std::string lane;
      for (;;) {
        if (stop_) return;
        Clock::time_point wake = Clock::time_point::max();
        if (TakeJob(&job, &lane, &wake)) break;
        if (wake == Clock::time_point::max())
          queue_cv_.wait(lock);
        else
          queue_cv_.wait_until(lock, wake);
      }
      ++running_jobs_;
      running_lane_ = std::move(lane);
    }
    try {
      job();
    } catch (const std::exception& e) {
      if (on_error_) on_error_(e.what());
    }
    job = nullptr;  // what the job held goes before the queue counts it done
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --running_jobs_;
      running_lane_.clear();
    }
    idle_cv_.notify_all();
  }
}

}  // namespace calibench::ui
