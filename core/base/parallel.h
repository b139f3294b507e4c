// A small work-sharing loop for per-pair feature extraction.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace calibench {

// The machine's hardware threads (at least 1): the default worker count everywhere. Results never
// depend on it (every parallel loop writes per-index slots and reduces them in index order).
int DefaultThreads();

// Runs body(i) for i in [0, count) on up to `threads` threads (the caller's included), each
// taking the next index when done. on_done(finished, i), if given, is called after each body
// under a lock, with the number finished so far.
void ParallelFor(size_t count, int threads, const std::function<void(size_t)>& body,
                 const std::function<void(int, size_t)>& on_done = {});

// Progress of a job over pairs: `done` of `total` finished, the last one `pair_id`.
using ProgressCallback = std::function<void(int done, int total, const std::string& pair_id)>;

}  // namespace calibench
