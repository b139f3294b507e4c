// A mutex that knows which thread holds it, so that a controller's "call with mutex_ held" is
// checked where it is written: AssertHeld stops the program, naming the function, when the
// calling thread does not hold the lock (docs/architecture.md, "Threads").
#pragma once

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

namespace calibench::ui {

class CheckedMutex {
 public:
  void lock() {
    mutex_.lock();
    owner_.store(std::this_thread::get_id(), std::memory_order_relaxed);
  }
  bool try_lock() {
    if (!mutex_.try_lock()) return false;
    owner_.store(std::this_thread::get_id(), std::memory_order_relaxed);
    return true;
  }
  void unlock() {
    owner_.store(std::thread::id(), std::memory_order_relaxed);
    mutex_.unlock();
  }
  // Relaxed is enough: only the holder writes its own id, and it clears it before unlocking, so a
  // thread reads its own id here exactly when it holds the lock.
  bool HeldByThisThread() const {
    return owner_.load(std::memory_order_relaxed) == std::this_thread::get_id();
  }
  // A broken locking rule is a bug that would otherwise show as a rare race: stop at once.
  void AssertHeld(const char* function) const {
    if (HeldByThisThread()) return;
    std::fprintf(stderr, "calibench: %s called without the controller's lock held\n", function);
    std::abort();
  }

 private:
  std::mutex mutex_;
  std::atomic<std::thread::id> owner_{};
};

}  // namespace calibench::ui
