// The sessions the workbench opened last, newest first: the File menu's "Recent". Kept in
// recent.json under $CALIBENCH_CONFIG_DIR, else $XDG_CONFIG_HOME/calibench, else
// ~/.config/calibench. No ImGui here.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace calibench::ui {

std::filesystem::path DefaultRecentFilesPath();

class RecentFiles {
 public:
  // Reads the list; a missing file is an empty list, an unreadable or malformed one too, with
  // load_error() saying why (the workbench shows it; the list is rewritten at the next Add).
  explicit RecentFiles(std::filesystem::path file = DefaultRecentFilesPath(),
                       std::size_t capacity = 10);

  // Newest first; files that no longer exist are left out.
  std::vector<std::filesystem::path> Paths() const;
  // Puts `path` (made absolute) first, keeps at most `capacity`, and writes the list atomically.
  // Returns why the write failed, empty on success (the menu keeps working in memory).
  std::string Add(const std::filesystem::path& path);
  const std::string& load_error() const { return load_error_; }
  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
  std::size_t capacity_;
  std::vector<std::filesystem::path> paths_;
  std::string load_error_;
};

}  // namespace calibench::ui
