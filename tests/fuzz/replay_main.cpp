// fuzz_replay TARGET PATH...: runs every file under the given files and folders through one fuzz
// target, as libFuzzer would, without libFuzzer. The test suite replays each corpus this way, so
// an input that once crashed a loader (kept in the corpus) keeps being checked on every build.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "tests/fuzz/harness.h"

namespace {

std::vector<uint8_t> ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  using calibench::fuzz::FindFuzzTarget;
  const calibench::fuzz::FuzzTarget* target = argc > 1 ? FindFuzzTarget(argv[1]) : nullptr;
  if (target == nullptr || argc < 3) {
    std::fprintf(stderr, "usage: fuzz_replay TARGET PATH...   (targets:");
    for (const auto& t : calibench::fuzz::FuzzTargets()) std::fprintf(stderr, " %s", t.name);
    std::fprintf(stderr, ")\n");
    return 2;
  }
  std::vector<std::filesystem::path> files;
  for (int i = 2; i < argc; ++i) {
    const std::filesystem::path path = argv[i];
    if (std::filesystem::is_directory(path)) {
      for (const auto& entry : std::filesystem::recursive_directory_iterator(path))
        if (entry.is_regular_file()) files.push_back(entry.path());
    } else {
      files.push_back(path);
    }
  }
  if (files.empty()) {
    std::fprintf(stderr, "fuzz_replay: no inputs under the given paths\n");
    return 2;
  }
  std::sort(files.begin(), files.end());  // a stable order for reproducible failures
  for (const auto& file : files) {
    const std::vector<uint8_t> bytes = ReadBytes(file);
    std::fprintf(stderr, "%s\n", file.c_str());  // the last name printed is the culprit
    calibench::fuzz::RunFuzzInput(*target, bytes.data(), bytes.size());
  }
  std::printf("%s: %zu inputs, no crash and no error other than IoError\n", target->name,
              files.size());
  return 0;
}
