#include "ui/state/work_queue.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <exception>

namespace calibench::ui {
namespace {
constexpr int kJobNiceness = 10;  // 0 normal .. 19 lowest
}  // namespace

WorkQueue::WorkQueue(std::function<void(const std::string&)> on_error)
    : on_error_(std::move(on_error)), worker_([this] { Loop(); }) {}

WorkQueue::~WorkQueue() { Stop(); }

void WorkQueue::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    queue_.clear();
  }
  queue_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
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

void WorkQueue::DropQueued() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.clear();
  }
  idle_cv_.notify_all();
}

void WorkQueue::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_cv_.wait(lock, [&] { return queue_.empty() && running_jobs_ == 0; });
}

bool WorkQueue::Busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !queue_.empty() || running_jobs_ > 0;
}

void WorkQueue::LowerPriority() {
  // On the worker itself: Linux's nice value is per thread, and threads it starts inherit it.
  Enqueue([] { setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kJobNiceness); });
}

void WorkQueue::Loop() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      queue_cv_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      ++running_jobs_;
    }
    try {
      job();
    } catch (const std::exception& e) {
      if (on_error_) on_error_(e.what());
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      --running_jobs_;
    }
    idle_cv_.notify_all();
  }
}

}  // namespace calibench::ui
