// A file browser drawn with ImGui (no native dialog package exists on the target systems): a
// modal over the workbench listing one folder (ui/state/folder_listing.h), with a path field, Up,
// Open and Cancel. Double-click walks into a folder or opens a file; Open takes the selected
// entry, or the folder shown when nothing is selected (a dataset or rosbag2 folder).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ui/state/folder_listing.h"

namespace calibench::ui {

class FileBrowser {
 public:
  // Shows the modal from the next Draw, at `folder` (its parent when it is a file).
  void Open(const std::filesystem::path& folder, const std::string& title);
  bool IsOpen() const { return open_; }
  // Draws the modal while open; returns the chosen path in the frame the user chooses it.
  std::optional<std::filesystem::path> Draw();

 private:
  void GoTo(const std::filesystem::path& folder);
  // Chooses `path` (closing the modal) when it can be opened; walks into a plain folder.
  std::optional<std::filesystem::path> Choose(const std::filesystem::path& path, bool folder);

  bool open_ = false;
  bool just_opened_ = false;
  std::string title_;
  std::filesystem::path folder_;
  std::vector<FolderEntry> entries_;
  int selected_ = -1;
  std::string typed_;  // the path field
  std::string error_;  // why the folder could not be listed
};

}  // namespace calibench::ui
