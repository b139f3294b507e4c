// WriteFileAtomically: a reader sees the old file or the new one, whole; writers never share a
// temporary, so two writing one path at once both finish and one of them wins whole; temporaries
// of killed writers are cleared. FileLock: one holder at a time, released when it dies.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/base/atomic_file.h"
#include "core/base/file_lock.h"
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

TEST(AtomicFile, TemporariesOfDeadWritersAreRemovedThoseOfLiveOnesKept) {
  const fs::path dir = test::TempDir("atomic_file_stale");
  const fs::path path = dir / "calibench.session.json";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) _exit(0);
  ASSERT_EQ(waitpid(child, nullptr, 0), child);
  const fs::path dead = path.string() + ".tmp." + std::to_string(child) + ".1.0";
  const fs::path live = path.string() + ".tmp." + std::to_string(getpid()) + ".1.0";
  std::ofstream(dead) << "half";
  std::ofstream(live) << "being written";
  std::ofstream(dir / "other.json.tmp.1.1.0") << "another file's";
  EXPECT_EQ(RemoveStaleTemporaries(path), 1);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(dir / "other.json.tmp.1.1.0"));
}

TEST(FileLock, OneHolderAtATimeAndTheHolderIsNamed) {
  const fs::path path = test::TempDir("file_lock") / "calibench.session.json";
  std::string holder;
  std::optional<FileLock> first = FileLock::TryLock(path, &holder);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->locked(), path);
  EXPECT_EQ(LockPathOf(path), fs::path(path.string() + ".lock"));
  // Another process (a second workbench) is refused and told who holds it.
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::string who;
    const bool refused = !FileLock::TryLock(path, &who).has_value();
    const bool named = who.find("pid " + std::to_string(getppid())) != std::string::npos;
    _exit(refused && named ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_FALSE(FileLock::TryLock(path, &holder).has_value());  // a second open file, too
  first.reset();
  EXPECT_TRUE(FileLock::TryLock(path, &holder).has_value());
}

TEST(FileLock, AKilledHolderLeavesNoStaleLock) {
  const fs::path path = test::TempDir("file_lock_killed") / "calibench.session.json";
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::string ignored;
    auto lock = FileLock::TryLock(path, &ignored);
    const char byte = lock ? 1 : 0;
    (void)!write(ready[1], &byte, 1);
    pause();
  }
  char byte = 0;
  ASSERT_EQ(read(ready[0], &byte, 1), 1);
  ASSERT_EQ(byte, 1);
  std::string holder;
  EXPECT_FALSE(FileLock::TryLock(path, &holder).has_value());
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  EXPECT_TRUE(FileLock::TryLock(path, &holder).has_value());
  close(ready[0]);
  close(ready[1]);
}

}  // namespace
}  // namespace calibench
