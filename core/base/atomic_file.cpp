#include "core/base/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <functional>
#include <string>
#include <thread>

#include "core/base/types.h"

namespace calibench {

namespace {

std::string TemporaryPrefix(const std::filesystem::path& path) {
  return path.filename().string() + ".tmp.";
}

// A name beside `path` that no other writer uses: process id, thread and a per-process counter.
// Two processes (or threads) writing one file each write their own temporary and the last rename
// wins whole, instead of one writing into the other's half-written temporary.
std::filesystem::path UniqueTemporary(const std::filesystem::path& path) {
  static std::atomic<unsigned long> counter{0};
  const auto thread = std::hash<std::thread::id>{}(std::this_thread::get_id()) & 0xffffff;
  return path.parent_path() / (TemporaryPrefix(path) + std::to_string(::getpid()) + "." +
                               std::to_string(thread) + "." + std::to_string(counter++));
}

std::string ErrnoText() { return std::strerror(errno); }

// Closes the descriptor on every path out; removes the named temporary unless released.
class Temporary {
 public:
  explicit Temporary(std::filesystem::path named) : named_(std::move(named)) {}
  ~Temporary() {
    if (fd >= 0) ::close(fd);
    if (linked_) ::unlink(named_.c_str());
  }
  int fd = -1;
  const std::filesystem::path& named() const { return named_; }
  void Linked() { linked_ = true; }
  bool linked() const { return linked_; }
  void Renamed() { linked_ = false; }

 private:
  std::filesystem::path named_;
  bool linked_ = false;
};

void WriteAll(int fd, const std::string& contents, const std::filesystem::path& path) {
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = ::write(fd, contents.data() + written, contents.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw IoError(path.string() + ": write failed: " + ErrnoText());
    written += static_cast<size_t>(n);
  }
  // On the disk before the rename: after a power cut the file is the old one or the new one,
  // never an empty new one (ext4 and xfs may commit the rename before the data otherwise).
  if (::fsync(fd) != 0) throw IoError(path.string() + ": write failed: " + ErrnoText());
}

// Opens the unnamed temporary, or (no O_TMPFILE here) the named one.
void OpenTemporary(const std::filesystem::path& path, Temporary* temporary) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  temporary->fd = ::open(folder.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0644);
  if (temporary->fd >= 0) return;
  temporary->fd = ::open(temporary->named().c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0644);
  if (temporary->fd < 0)
    throw IoError(path.string() +
                  ": cannot write (is the folder there and writable?): " + ErrnoText());
  temporary->Linked();
}

}  // namespace

void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents) {
  Temporary temporary(UniqueTemporary(path));
  OpenTemporary(path, &temporary);
  WriteAll(temporary.fd, contents, path);
  if (!temporary.linked()) {
    // Opened unnamed: /proc/self/fd/N gives it its name without privileges.
    const std::string proc = "/proc/self/fd/" + std::to_string(temporary.fd);
    if (::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, temporary.named().c_str(), AT_SYMLINK_FOLLOW) !=
        0)
      throw IoError(path.string() + ": cannot write: " + ErrnoText());
    temporary.Linked();
  }
  if (::rename(temporary.named().c_str(), path.c_str()) != 0)
    throw IoError(path.string() + ": cannot replace the file: " + ErrnoText());
  temporary.Renamed();
  RemoveStaleTemporaries(path);  // what an earlier writer, killed in that instant, left
}

int RemoveStaleTemporaries(const std::filesystem::path& path) {
  const std::string prefix = TemporaryPrefix(path);
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  int removed = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const pid_t pid = static_cast<pid_t>(std::atol(name.c_str() + prefix.size()));
    if (pid > 0 && (::kill(pid, 0) == 0 || errno == EPERM)) continue;  // its writer still runs
    if (std::filesystem::remove(entry.path(), ec)) ++removed;
  }
  return removed;
}

}  // namespace calibench
