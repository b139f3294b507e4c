// The libFuzzer entry point of one target; CALIBENCH_FUZZ_TARGET names it (tests/fuzz/CMakeLists).
#include <cstdio>
#include <cstdlib>

#include "tests/fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const calibench::fuzz::FuzzTarget* target =
      calibench::fuzz::FindFuzzTarget(CALIBENCH_FUZZ_TARGET);
  if (target == nullptr) {
    std::fprintf(stderr, "no fuzz target named %s\n", CALIBENCH_FUZZ_TARGET);
    std::abort();
  }
  return calibench::fuzz::RunFuzzInput(*target, data, size);
}
