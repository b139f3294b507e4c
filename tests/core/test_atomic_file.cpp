// WriteFileAtomically: a reader sees the old file or the new one, whole; writers never share a
// temporary, so two writing one path at once both finish and one of them wins whole.
#include <gtest/gtest.h>

#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/types.h"
#include "tests/test_support.h"

namespace calibench {
namespace {
namespace fs = std::filesystem;

TEST(AtomicFile, TwoWritersOfOnePathBothFinishAndOneWinsWhole) {
  const fs::path path = test::TempDir("atomic_file_writers") / "result.json";
  const std::string a(200000, 'a'), b(150000, 'b');
  std::vector<std::thread> writers;
  int failures = 0;
  std::mutex failures_mutex;
  for (const std::string* contents : {&a, &b})
    writers.emplace_back([&, contents] {
      for (int round = 0; round < 50; ++round) {
        try {
          WriteFileAtomically(path, *contents);
        } catch (const IoError&) {
          std::lock_guard<std::mutex> lock(failures_mutex);
          ++failures;
        }
      }
    });
  for (std::thread& writer : writers) writer.join();
  EXPECT_EQ(failures, 0);
  const std::string final_contents = test::ReadFileBytes(path);
  EXPECT_TRUE(final_contents == a || final_contents == b) << final_contents.size() << " bytes";
  EXPECT_TRUE(test::TemporariesBeside(path).empty());
}

TEST(AtomicFile, UnwritableFolderFailsNamingTheFileAndLeavesNothing) {
  const fs::path dir = test::TempDir("atomic_file_missing");
  const fs::path path = dir / "no_such_folder" / "result.json";
  try {
    WriteFileAtomically(path, "{}");
    ADD_FAILURE() << "no IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace calibench
