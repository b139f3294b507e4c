// An advisory lock (flock) that keeps two processes from editing one file: the workbench holds
// one on <session>.lock while a session is open. The kernel drops it when the process ends, a
// crash or a kill included, so a lock is never left stale.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace calibench {

class FileLock {
 public:
  // Locks `path`.lock (created when missing, and left in place: removing a lock file races with
  // a process that is about to lock it). On success the lock file holds "pid <n> on <host>". When
  // another process holds it, returns nullopt and sets *holder to that text. Throws IoError naming
  // the lock file when it cannot be created (read-only folder).
  static std::optional<FileLock> TryLock(const std::filesystem::path& path, std::string* holder);

  FileLock(FileLock&& other) noexcept;
  FileLock& operator=(FileLock&& other) noexcept;
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock();

  const std::filesystem::path& locked() const { return path_; }  // the file it protects

 private:
  FileLock(std::filesystem::path path, int fd) : path_(std::move(path)), fd_(fd) {}
  std::filesystem::path path_;
  int fd_ = -1;
};

std::filesystem::path LockPathOf(const std::filesystem::path& path);

}  // namespace calibench
