#include "app/progress_listener.h"

#include <mutex>

namespace calibench::app {

namespace {
std::mutex listener_mutex;
ProgressListener& Listener() {
  static ProgressListener listener;
  return listener;
}
}  // namespace

void SetProgressListener(ProgressListener listener) {
  std::lock_guard lock(listener_mutex);
  Listener() = std::move(listener);
}

void NotifyProgress(const std::string& phase, std::int64_t done, std::int64_t total,
                    const std::string& item) {
  ProgressListener listener;
  {
    std::lock_guard lock(listener_mutex);
    listener = Listener();
  }
  if (listener) listener(phase, done, total, item);
}

}  // namespace calibench::app
