#include "core/base/notice.h"

#include <cstdio>
#include <map>
#include <mutex>

namespace calibench {
namespace {

std::mutex& NoticeMutex() {
  static std::mutex mutex;
  return mutex;
}

std::map<std::string, int, std::less<>>& Counts() {
  static std::map<std::string, int, std::less<>> counts;
  return counts;
}

}  // namespace

void NoteOnce(std::string_view kind, const std::string& text) {
  std::lock_guard lock(NoticeMutex());
  auto [it, first] = Counts().try_emplace(std::string(kind), 0);
  ++it->second;
  if (!first) return;
  std::fprintf(stderr, "note: %s (said once; other files like it are read the same way)\n",
               text.c_str());
  std::fflush(stderr);
}

int NotedCount(std::string_view kind) {
  std::lock_guard lock(NoticeMutex());
  const auto it = Counts().find(kind);
  return it == Counts().end() ? 0 : it->second;
}

}  // namespace calibench
