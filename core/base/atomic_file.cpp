#include "core/base/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include "core/base/types.h"

namespace calibench {

namespace {

// A name beside `path` that no other writer uses: process id, thread and a per-process counter.
// Two processes (or threads) writing one file each write their own temporary and the last rename
// wins whole, instead of one writing into the other's half-written temporary.
std::filesystem::path UniqueTemporary(const std::filesystem::path& path) {
  static std::atomic<unsigned long> counter{0};
  const auto thread = std::hash<std::thread::id>{}(std::this_thread::get_id()) & 0xffffff;
  return path.string() + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(thread) + "." +
         std::to_string(counter++);
}

}  // namespace

void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents) {
  const std::filesystem::path temporary = UniqueTemporary(path);
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(path.string() + ": cannot write (is the folder there and writable?)");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) {
      out.close();
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw IoError(path.string() + ": write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw IoError(path.string() + ": cannot replace the file: " + ec.message());
  }
}

}  // namespace calibench
