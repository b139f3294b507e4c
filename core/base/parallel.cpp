#include "core/base/parallel.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>
#include <vector>

namespace calibench {

int DefaultThreads() { return std::max(1, static_cast<int>(std::thread::hardware_concurrency())); }

void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& body,
                 const std::function<void(int, size_t)>& on_done) {
  std::atomic<size_t> next{0};
  int finished = 0;
  std::mutex done_mutex;
  auto worker = [&] {
    for (size_t i = next++; i < count; i = next++) {
      body(i);
      if (on_done) {
        std::lock_guard<std::mutex> lock(done_mutex);
        on_done(++finished, i);
      }
    }
  };
  const int num_threads = std::max(1, std::min<int>(threads, static_cast<int>(count)));
  std::vector<std::thread> pool;
  for (int t = 1; t < num_threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
}

}  // namespace calibench
