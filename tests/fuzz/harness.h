// The loaders under fuzzing, one entry per file kind. Each entry hands the bytes to a loader as a
// file (the loaders take paths, as users give them) and accepts exactly one outcome besides
// success: an IoError, which is what bad user input must produce. Anything else -- another
// exception type, a crash, a sanitizer report, an allocation beyond the fuzzer's limit -- is a
// finding. Used by libFuzzer (libfuzzer_main.cpp, -DCALIBENCH_FUZZ=ON) and by the corpus replay
// that every build runs as a test (replay_main.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace calibench::fuzz {

struct FuzzTarget {
  const char* name;       // the corpus folder: tests/fuzz/corpus/<name>/
  const char* extension;  // the loaders choose their parser by it
  void (*load)(const std::vector<uint8_t>& bytes);
};

const std::vector<FuzzTarget>& FuzzTargets();
// nullptr when no target has that name.
const FuzzTarget* FindFuzzTarget(std::string_view name);
// Runs one input; returns 0 (libFuzzer's convention) when the loader succeeded or threw IoError.
int RunFuzzInput(const FuzzTarget& target, const uint8_t* data, size_t size);

}  // namespace calibench::fuzz
