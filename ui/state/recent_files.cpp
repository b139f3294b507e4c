#include "ui/state/recent_files.h"

#include <algorithm>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "core/base/atomic_file.h"
#include "core/base/types.h"
#include "core/io/json_io.h"

namespace calibench::ui {
namespace fs = std::filesystem;

fs::path DefaultRecentFilesPath() {
  if (const char* dir = std::getenv("CALIBENCH_CONFIG_DIR"); dir && *dir)
    return fs::path(dir) / "recent.json";
  if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && *xdg)
    return fs::path(xdg) / "calibench" / "recent.json";
  const char* home = std::getenv("HOME");
  return fs::path(home && *home ? home : "/tmp") / ".config" / "calibench" / "recent.json";
}

RecentFiles::RecentFiles(fs::path file, std::size_t capacity)
    : file_(std::move(file)), capacity_(capacity) {
  std::error_code error;
  if (!fs::exists(file_, error)) return;
  try {
    const nlohmann::json document = json_io::ReadJson(file_);
    if (!document.is_object() || !document.contains("recent") || !document["recent"].is_array())
      throw IoError(file_.string() + ": not a list of recent sessions (\"recent\": [...])");
    for (const nlohmann::json& entry : document["recent"])
      if (entry.is_string() && paths_.size() < capacity_)
        paths_.emplace_back(entry.get<std::string>());
  } catch (const IoError& e) {
    load_error_ = e.what();
    paths_.clear();
  }
}

std::vector<fs::path> RecentFiles::Paths() const {
  std::vector<fs::path> existing;
  std::error_code error;
  for (const fs::path& path : paths_)
    if (fs::exists(path, error)) existing.push_back(path);
  return existing;
}

std::string RecentFiles::Add(const fs::path& path) {
  const fs::path absolute = fs::absolute(path).lexically_normal();
  std::erase(paths_, absolute);
  paths_.insert(paths_.begin(), absolute);
  if (paths_.size() > capacity_) paths_.resize(capacity_);
  nlohmann::json list = nlohmann::json::array();
  for (const fs::path& entry : paths_) list.push_back(entry.string());
  try {
    std::error_code error;
    fs::create_directories(file_.parent_path(), error);
    WriteFileAtomically(file_, nlohmann::json{{"recent", list}}.dump(2) + "\n");
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

}  // namespace calibench::ui
